// Strong-force network ("force chains", seed 004 Fig. 4.55: red lines for normal contact forces
// above the mean, line width proportional to the force). A contact is strong when |Fn| exceeds
// the threshold: the mean |Fn| of the considered contacts times a factor (default 1), or a force
// given in N. Chains are the connected groups of particles joined by strong particle–particle
// contacts (union–find); their sizes count particles.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "love_weber_stress.hpp"
#include "selection.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

struct ChainOptions {
  double threshold_n = -1.0;  // N; < 0: mean |Fn| times mean_factor
  double mean_factor = 1.0;
  bool walls = false;  // also wall contacts (segment centre -> contact point)
};

struct ForceChains {
  std::vector<std::int32_t> branch;   // index into the branches, per segment
  std::vector<Eigen::Vector3d> a, b;  // segment ends (centre to centre / contact point)
  std::vector<double> fn, fs;         // |Fn|, |Fs| (N)
  std::vector<std::uint8_t> strong;
  std::vector<std::int32_t> chain;  // chain id of a strong particle contact, else -1
  double mean_fn = 0.0, max_fn = 0.0, threshold = 0.0;
  std::size_t strong_count = 0, chains = 0, largest_chain = 0;
};

/// Segments of all contacts (of `branches`; wall contacts only with options.walls) with their
/// forces, the threshold and the chains. Throws std::invalid_argument on a bad threshold.
ForceChains force_chains(const Frame& frame, const ContactBranches& branches,
                         const ChainOptions& options);

/// Throws InputError naming `file` and the option (--threshold, --mean-factor) when `options`
/// is invalid (threshold_n -1 = unset).
void check_chain_options(const std::string& file, const ChainOptions& options);

/// `analyze chains` as one call (CLI and Python): the chains of the contacts whose point lies
/// in `sel`. Throws InputError naming `file`: bad options, no contact in the selection.
ForceChains force_chains_in(const std::string& file, const Frame& frame, const Selection& sel,
                            const ChainOptions& options);

}  // namespace gs::analysis
