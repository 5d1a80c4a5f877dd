#include "slab_options.hpp"

namespace gs::cli {

void add_slab_options(CLI::App* s, SlabArgs& a) {
  s->add_option("--slab-origin", a.origin, "slab mid-plane point x y z")->expected(3);
  s->add_option("--slab-normal", a.normal, "slab normal x y z")->expected(3);
  s->add_option("--slab-axis", a.axis, "in-plane x axis x y z")->expected(3);
  s->add_option("--slab-thickness", a.thickness, "slab thickness in m");
  s->add_option("--slab-d50", a.d50_multiple, "slab thickness in units of d50 (seed 000: 5)");
}

}  // namespace gs::cli
