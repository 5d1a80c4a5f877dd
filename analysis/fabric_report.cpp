#include "fabric_report.hpp"

#include <stdexcept>
#include <vector>

#include "errors.hpp"

namespace gs::analysis {

FabricReport fabric_report(const std::string& file, const Frame& f, const Selection& sel) {
  const auto b = selected_branches(f, contact_branches(f), sel, false);
  std::vector<Eigen::Vector3d> normals;
  for (const auto& br : b.branches)
    normals.push_back(f.contacts[static_cast<std::size_t>(br.contact)].normal);
  Frame sub = f;  // particles (for N_p and the clump members) and clump bodies of the selection
  sub.particles.clear();
  sub.clumps.clear();
  for (const auto& p : f.particles)
    if (sel.contains(p.position)) sub.particles.push_back(p);
  for (const auto& c : f.clumps)
    if (sel.contains(c.position)) sub.clumps.push_back(c);
  FabricReport r;
  try {
    r.contacts = contact_fabric(normals, sub.particles.size(), f.two_d ? 2 : 3);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, std::string(e.what()) + " (empty selection?)");
  }
  // Particle-orientation fabric D^p (seed 003 §4.3, eq 20–21): from the clump bodies when the
  // frame has them (selected by centre of mass), else from the members (selected one by one).
  r.orientation = f.clumps.empty() ? member_orientation_fabric(sub)
                                   : body_orientation_fabric(sub.clumps, r.contacts.dim);
  r.view_axes = view_axes(f, sel.slab);
  return r;
}

}  // namespace gs::analysis
