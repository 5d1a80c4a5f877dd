// The contact pass's gather with AVX-512 gather instructions: a contact batch's lanes filled in
// eights from the pairs' histories and parameters and the sphere pairs' bodies, instead of one
// scalar copy per lane and field (Simulation::prepare_pair). The values are copies, so the
// batch holds the same bits either way; only the speed differs.
#pragma once

#include <cstdint>

#include "cohesive_frictional_law.hpp"
#include "dem_types.hpp"

namespace gs::solver {

/// Where the lanes' values come from.
struct LaneSources {
  const ParticleState* particles = nullptr;
  const ContactHistory* hist = nullptr;   // per pair
  const ContactParams* params = nullptr;  // per pair
  bool ktw = false;    // KTW too (Hertz–Mindlin's βs, or the twisting stiffness)
  bool twist = false;  // TX, KTW and MAX_TWIST (twisting moments on)
};

/// Whether gather_lanes runs here: an x86 build, and the SIMD level chosen (simd_level.hpp) is
/// AVX-512.
bool lane_gather_available();

/// Fills lanes [0, count) (count ≤ ContactBatch::kLanes) of `batch`:
/// - every lane from its pair pair[j]'s history and parameters: FRESH (1 where the history is
///   not real), ONX…, SX…, BX…, KN, KS, KR, TAN_FRICTION, MAX_ROLL, and with `ktw` KTW, with
///   `twist` TX…, KTW, MAX_TWIST;
/// - the lanes whose bit is set in `sphere` (sphere pairs) from bodies a[j] and b[j]: GEOM = 1,
///   RATCHET = 1, X1…, X2…, R1, R2, V1…, V2…, W1…, W2… (a periodic cell's image shift is not
///   applied: the caller keeps the scalar copies there). The other lanes keep what these fields
///   hold (the caller writes a wall lane's before).
/// Requires lane_gather_available().
void gather_lanes(const LaneSources& s, const std::int64_t* pair, const std::int64_t* a,
                  const std::int64_t* b, std::uint32_t sphere, int count, ContactBatch& batch);

}  // namespace gs::solver
