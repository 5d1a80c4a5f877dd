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
/// REV maps and shear zones.
void bind_maps(pybind11::module_& m);
/// Strain, void cells, HHD and vortex series of a frame's motion.
void bind_motion(pybind11::module_& m);
/// Scenes: load with values set over the file, run with progress, stop and resume.
void bind_simulation(pybind11::module_& m);
/// Scene reports: silo, interface shear zone, materials.
void bind_reports(pybind11::module_& m);
/// Subset DIC of images.
void bind_dic(pybind11::module_& m);

}  // namespace gs::py_bind
