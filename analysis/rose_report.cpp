#include "rose_report.hpp"

#include <cmath>
#include <stdexcept>

#include "errors.hpp"

namespace gs::analysis {

void check_rose_spec(const std::string& file, const RoseSpec& a) {
  const double k = 360.0 / a.bin_deg;
  if (!(a.bin_deg > 0.0) || !std::isfinite(a.bin_deg) || std::abs(k - std::round(k)) > 1e-9 ||
      std::round(k) < 2)
    throw InputError(file, "--bin-deg must divide 360 into 2 or more bins", value_str(a.bin_deg));
  if (a.bins3d.size() != 2 || a.bins3d[0] < 1 || a.bins3d[1] < 1)
    throw InputError(file, "--bins3d needs two counts >= 1");
}

RoseReport rose_report(const std::string& file, const Frame& f, const Selection& sel,
                       const RoseSpec& a) {
  check_rose_spec(file, a);
  RoseReport r;
  r.axes = view_axes(f, sel.slab);
  if (!a.plane_normal.empty() || !a.plane_axis.empty()) {
    if (f.two_d) throw InputError(file, "--plane-* is for 3D frames (2D: the x-y plane)");
    for (const auto* v : {&a.plane_normal, &a.plane_axis})
      if (!v->empty() && v->size() != 3) throw InputError(file, "--plane-* needs 3 numbers");
    Slab p;
    p.thickness = 1.0;
    p.normal = a.plane_normal.empty() ? Eigen::Vector3d(r.axes.row(2))
                                      : Eigen::Vector3d(a.plane_normal.data());
    p.axis1 = a.plane_axis.empty() ? Eigen::Vector3d(r.axes.row(0))
                                   : Eigen::Vector3d(a.plane_axis.data());
    try {
      r.axes = slab_axes(p);
    } catch (const std::invalid_argument& e) {
      throw InputError(file, e.what());
    }
  }
  const auto b = selected_branches(f, contact_branches(f), sel, a.walls);
  std::vector<RoseContact> rc;
  for (const auto& br : b.branches) {
    const Contact& c = f.contacts[static_cast<std::size_t>(br.contact)];
    rc.push_back({c.normal, c.normal_force.norm(), c.shear_force.norm()});
  }
  if (rc.empty()) throw InputError(file, "no contact in the selection (empty selection)");
  r.rose2d = contact_rose_2d(rc, r.axes, static_cast<int>(std::round(360.0 / a.bin_deg)));
  if (a.three_d) {
    if (f.two_d) throw InputError(file, "--3d needs a 3D frame");
    r.rose3d = contact_rose_3d(rc, r.axes, a.bins3d[0], a.bins3d[1]);
  }
  return r;
}

}  // namespace gs::analysis
