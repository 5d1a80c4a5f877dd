// YADE's Law2_ScGeom6D_CohFrictPhys_CohesionMoment for non-cohesive contacts, incremental form
// (seed 000 eq 1-7; seed 004 eqs 3.1-3.18). docs/physics.md lists each convention.
#pragma once

#include <cmath>

#include "dem_types.hpp"
#include "scalar_vec3.hpp"

namespace gs::solver {

/// Constant contact parameters, set when the contact is created.
struct ContactParams {
  double kn = 0, ks = 0, kr = 0, ktw = 0;
  double tan_friction = 0;
  double max_roll = -1;   // η·R_roll (m); negative: rolling moment unbounded
  double max_twist = -1;  // likewise for twisting
};

/// The parameters of a contact between radii r1 and r2 (a wall passes the sphere's radius, a
/// YADE facet 2R): modulus-based (contact_stiffness) or, with m.normal_stiffness_N_m > 0, the
/// constant Kn and Ks = νc·Kn of seed 003 §2.4 (Kr = β·Ks·r1·r2 either way).
ContactParams contact_params(const Material& m, double r1, double r2, double twist_beta,
                             double twist_eta);

/// Kinematics of a body at a contact.
struct BodyMotion {
  V3 pos, vel, angvel;
};

/// Loads one contact puts on its bodies, split as YADE accumulates them: body 1 receives
/// force1 and the torques arm1 − moment; body 2 receives −force1 and arm2 + moment.
struct ContactLoads {
  V3 force1, arm1, arm2, moment;
  double friction_dissipation = 0, rolling_dissipation = 0;  // J, this step
};

/// The law's inputs and outputs for a batch of contacts, one array per component (structure
/// of arrays), so that the compiler vectorises the law across contacts. Lane j holds one
/// contact: its geometry, the motion of its two bodies, its history and its parameters.
/// Body 1 is the wall for wall contacts; the normal points from body 1 to body 2.
/// On GEOM lanes (sphere pairs) the batch computes the geometry itself, as
/// sphere_sphere_geometry does and in its order of operations, so the square roots and
/// divisions run across lanes: NX, PEN, C1, C2 and PT are written from X1, X2, R1 and R2, and
/// TOUCH says whether the pair touches (the law's loads of a lane that does not are garbage).
/// Other lanes bring NX, PEN, C1, C2 and PT filled in and come out with TOUCH = 1.
struct ContactBatch {
  static constexpr int kLanes = 32;
  // clang-format off
  enum Field : int {
    // inputs
    NX, NY, NZ,     // unit normal
    PEN,            // penetration (≥ 0), m
    R1, R2,         // radii (both the sphere's for wall contacts)
    RATCHET,        // 1: relative velocity from the radii (YADE avoidGranularRatcheting)
    V1X, V1Y, V1Z,  // velocities
    V2X, V2Y, V2Z,
    W1X, W1Y, W1Z,  // angular velocities
    W2X, W2Y, W2Z,
    C1X, C1Y, C1Z,  // contact point − centre of body 1 (torque arm)
    C2X, C2Y, C2Z,  // contact point − centre of body 2
    FRESH,          // 1: the contact is new this step (history starts at zero)
    SVX, SVY, SVZ,  // periodic cell: velocity of body 2's image relative to body 2 (else unset)
    ONX, ONY, ONZ,  // last step's normal
    GEOM,           // 1: a sphere pair whose geometry the batch computes from X1, X2 (below)
    X1X, X1Y, X1Z,  // GEOM lanes: the centres (body 2's image on a periodic cell)
    X2X, X2Y, X2Z,
    KN, KS, KR, KTW, TAN_FRICTION, MAX_ROLL, MAX_TWIST,  // KTW, MAX_TWIST: only with `twist`
    // history: read, and written back with this step's values
    SX, SY, SZ,     // shear force
    BX, BY, BZ,     // bending moment
    TX, TY, TZ,     // twisting moment (only with `twist`)
    // outputs
    F1X, F1Y, F1Z,  // force on body 1
    A1X, A1Y, A1Z,  // torque on body 1 from the force (arm1)
    A2X, A2Y, A2Z,  // torque on body 2 from the force (arm2)
    MX, MY, MZ,     // contact moment (body 1 receives −M, body 2 +M)
    FN,             // |normal force|
    FRICTION_DISSIPATION, ROLLING_DISSIPATION,
    PTX, PTY, PTZ,  // contact point (GEOM lanes; the others pass theirs through)
    TOUCH,          // 1: the pair touches (GEOM lanes: distinct centres, penetration ≥ 0)
    kFields
  };
  // clang-format on

  alignas(64) double v[kFields][kLanes];
  double* operator[](Field f) { return v[f]; }
  /// The 3-vector whose x component is field f, in lane j (y and z follow it).
  V3 get3(Field f, int j) const { return {v[f][j], v[f + 1][j], v[f + 2][j]}; }
  void set3(Field f, int j, const V3& x) {
    v[f][j] = x.x;
    v[f + 1][j] = x.y;
    v[f + 2][j] = x.z;
  }
};

/// The geometry of lane j (what both contact laws start from): on GEOM lanes (sphere pairs)
/// sphere_sphere_geometry's operations, lane by lane, written back to NX, PEN, PTX and TOUCH (a
/// lane that is not a sphere pair computes them on whatever X1, X2 hold and selects its own
/// fields instead, with TOUCH = 1).
struct LaneGeometry {
  V3 n, pt, c1, c2;  // unit normal, contact point, arms from the centres of body 1 and 2
  double pen = 0;    // penetration, m
};

[[gnu::always_inline]] inline LaneGeometry lane_geometry(ContactBatch& b, int j) {
  using F = ContactBatch::Field;
  auto in3 = [&](F f) { return b.get3(f, j); };
  auto out3 = [&](F f, const V3& x) { b.set3(f, j, x); };
  const double r1 = b.v[F::R1][j], r2 = b.v[F::R2][j];
  const bool geom = b.v[F::GEOM][j] != 0;
  const V3 x1 = in3(F::X1X), x2 = in3(F::X2X);
  const V3 branch = x2 - x1;
  const double dist = std::sqrt(squared_norm(branch));
  const V3 n_s = branch / dist;
  const double pen_s = r1 + r2 - dist;
  const V3 pt_s = x1 + (r1 - 0.5 * pen_s) * n_s;
  LaneGeometry g;
  g.n = select(geom, n_s, in3(F::NX));
  g.pen = geom ? pen_s : b.v[F::PEN][j];
  g.pt = select(geom, pt_s, in3(F::PTX));
  g.c1 = select(geom, pt_s - x1, in3(F::C1X));
  g.c2 = select(geom, pt_s - x2, in3(F::C2X));
  b.v[F::TOUCH][j] = ((!geom) | ((dist > 0) & !(pen_s < 0))) ? 1.0 : 0.0;
  out3(F::NX, g.n);
  b.v[F::PEN][j] = g.pen;
  out3(F::PTX, g.pt);
  return g;
}

/// One step of the law on lanes [0, count) of the batch (seed 000 eq 1-7): rotation of the
/// stored shear force and moments into the current tangent plane, elastic increments, Coulomb
/// and rolling limits, and the loads. Every lane computes both sides of each condition and
/// selects, with the operations of each lane in the order of the scalar law, so results do not
/// depend on the batching. Compiled for AVX-512, AVX2 and plain x86-64; the variant is
/// simd_level() (the best the CPU has unless GS_SIMD or set_simd_level says otherwise), and
/// every variant gives the same bits.
/// `twist`: twisting moments are enabled. Without it KTW, MAX_TWIST and TX..TZ are not read
/// (the caller need not fill them) and the twisting moments come out zero.
/// `periodic`: body 2 is an image across a periodic cell's faces, moving with SV relative to
/// the body (YADE's getIncidentVel with shiftVel: α·SV added to the relative velocity).
void cohesive_frictional_batch(ContactBatch& batch, int count, double dt, bool twist,
                               bool periodic = false);

}  // namespace gs::solver
