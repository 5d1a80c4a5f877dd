#include "slab_options.hpp"

#include "grain_size.hpp"

namespace gs::cli {

void add_slab_options(CLI::App* s, SlabArgs& a) {
  s->add_option("--slab-origin", a.origin, "slab mid-plane point x y z")->expected(3);
  s->add_option("--slab-normal", a.normal, "slab normal x y z")->expected(3);
  s->add_option("--slab-axis", a.axis, "in-plane x axis x y z")->expected(3);
  s->add_option("--slab-thickness", a.thickness, "slab thickness in m");
  s->add_option("--slab-d50", a.d50_multiple, "slab thickness in units of d50 (seed 000: 5)");
}

analysis::Slab make_slab(const SlabArgs& a, const Frame& frame) {
  analysis::Slab s;
  if (a.origin.size() == 3) s.origin = Eigen::Vector3d(a.origin.data());
  if (a.normal.size() == 3) s.normal = Eigen::Vector3d(a.normal.data());
  if (a.axis.size() == 3) s.axis1 = Eigen::Vector3d(a.axis.data());
  s.thickness = a.thickness;
  if (a.d50_multiple > 0.0) s.thickness = a.d50_multiple * analysis::d50(frame);
  return s;
}

}  // namespace gs::cli
