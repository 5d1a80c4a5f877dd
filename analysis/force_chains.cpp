// Strong-force network (seed 004 Fig. 4.55).
#include "force_chains.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "errors.hpp"

namespace gs::analysis {
namespace {

std::int32_t root(std::vector<std::int32_t>& parent, std::int32_t i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace

ForceChains force_chains(const Frame& frame, const ContactBranches& branches,
                         const ChainOptions& opt) {
  if (!std::isfinite(opt.threshold_n) || !(opt.mean_factor >= 0.0) ||
      !std::isfinite(opt.mean_factor)) {
    throw std::invalid_argument("force chains: threshold must be finite and the factor >= 0");
  }
  ForceChains fc;
  double sum = 0.0;
  for (std::size_t k = 0; k < branches.branches.size(); ++k) {
    const ContactBranch& b = branches.branches[k];
    if (b.p2 < 0 && !opt.walls) continue;
    const Contact& c = frame.contacts[static_cast<std::size_t>(b.contact)];
    fc.branch.push_back(static_cast<std::int32_t>(k));
    fc.a.push_back(b.start);
    fc.b.push_back(b.start + b.branch);
    fc.fn.push_back(c.normal_force.norm());
    fc.fs.push_back(c.shear_force.norm());
    sum += fc.fn.back();
    fc.max_fn = std::max(fc.max_fn, fc.fn.back());
  }
  const std::size_t n = fc.fn.size();
  fc.mean_fn = n > 0 ? sum / static_cast<double>(n) : 0.0;
  fc.threshold = opt.threshold_n >= 0.0 ? opt.threshold_n : opt.mean_factor * fc.mean_fn;
  fc.strong.assign(n, 0);
  fc.chain.assign(n, -1);
  std::vector<std::int32_t> parent(frame.particles.size());
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::uint8_t> in_chain(frame.particles.size(), 0);
  for (std::size_t s = 0; s < n; ++s) {
    if (!(fc.fn[s] > fc.threshold)) continue;
    fc.strong[s] = 1;
    ++fc.strong_count;
    const ContactBranch& b = branches.branches[static_cast<std::size_t>(fc.branch[s])];
    if (b.p2 < 0) continue;
    in_chain[static_cast<std::size_t>(b.p1)] = in_chain[static_cast<std::size_t>(b.p2)] = 1;
    const std::int32_t r1 = root(parent, b.p1), r2 = root(parent, b.p2);
    if (r1 != r2) parent[static_cast<std::size_t>(std::max(r1, r2))] = std::min(r1, r2);
  }
  // Chain ids in order of their smallest particle index; sizes in particles.
  std::vector<std::int32_t> id(frame.particles.size(), -1);
  std::vector<std::size_t> size;
  for (std::size_t i = 0; i < frame.particles.size(); ++i) {
    if (!in_chain[i]) continue;
    const auto r = static_cast<std::size_t>(root(parent, static_cast<std::int32_t>(i)));
    if (id[r] < 0) {
      id[r] = static_cast<std::int32_t>(size.size());
      size.push_back(0);
    }
    ++size[static_cast<std::size_t>(id[r])];
  }
  for (std::size_t s = 0; s < n; ++s) {
    const ContactBranch& b = branches.branches[static_cast<std::size_t>(fc.branch[s])];
    if (fc.strong[s] && b.p2 >= 0) fc.chain[s] = id[static_cast<std::size_t>(root(parent, b.p1))];
  }
  fc.chains = size.size();
  fc.largest_chain = size.empty() ? 0 : *std::max_element(size.begin(), size.end());
  return fc;
}

void check_chain_options(const std::string& file, const ChainOptions& o) {
  if (o.threshold_n != -1.0 && !(o.threshold_n >= 0.0 && std::isfinite(o.threshold_n)))
    throw InputError(file, "--threshold must be a force >= 0 in N", value_str(o.threshold_n));
  if (!(o.mean_factor >= 0.0) || !std::isfinite(o.mean_factor))
    throw InputError(file, "--mean-factor must be >= 0", value_str(o.mean_factor));
}

ForceChains force_chains_in(const std::string& file, const Frame& frame, const Selection& sel,
                            const ChainOptions& options) {
  check_chain_options(file, options);
  const auto b = selected_branches(frame, contact_branches(frame), sel, options.walls);
  if (b.branches.empty()) throw InputError(file, "no contact in the selection (empty selection)");
  return force_chains(frame, b, options);
}

}  // namespace gs::analysis
