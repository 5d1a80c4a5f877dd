// The pieces of the compiled module, one file each.
#pragma once

#include <pybind11/pybind11.h>

namespace gs::py_bind {

/// granoscope.Error (a ValueError) for gs::InputError, with the CLI's one-line message.
void bind_errors(pybind11::module_& m);
/// Frame, Trajectory, read/write of every snapshot format.
void bind_data(pybind11::module_& m);
/// Analyses of frames.
void bind_analysis(pybind11::module_& m);
/// Subset DIC of images.
void bind_dic(pybind11::module_& m);

}  // namespace gs::py_bind
