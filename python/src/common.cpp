#include "common.hpp"

#include <pybind11/pybind11.h>

#include "errors.hpp"
#include "grain_size.hpp"

namespace gs::py_bind {

void raise_pending_signal() {
  pybind11::gil_scoped_acquire locked;
  if (PyErr_CheckSignals() != 0) throw pybind11::error_already_set();
}

double frame_d50(const Frame& f, std::optional<double> d50) {
  if (d50) {
    analysis::require_positive(kFrame, "--d50", *d50);
    return *d50;
  }
  if (f.particles.empty()) throw InputError(kFrame, "the frame has no particles");
  return analysis::d50(f);
}

analysis::SelectionSpec selection_spec(bool slab, const OptVec& slab_origin,
                                       const OptVec& slab_normal, const OptVec& slab_axis,
                                       std::optional<double> slab_thickness,
                                       std::optional<double> slab_d50, const OptVec& region) {
  analysis::SelectionSpec spec;
  spec.slab = slab;
  spec.slab_origin = slab_origin.value_or(std::vector<double>{});
  spec.slab_normal = slab_normal.value_or(std::vector<double>{});
  spec.slab_axis = slab_axis.value_or(std::vector<double>{});
  spec.slab_thickness = slab_thickness;
  spec.slab_d50 = slab_d50;
  spec.region = region.value_or(std::vector<double>{});
  return spec;
}

}  // namespace gs::py_bind
