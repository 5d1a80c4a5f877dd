// The compiled half of the Python package `granoscope` (pybind11): frames and trajectories with
// numpy views of their fields, the readers and writers of io/, and analyses. The pure-Python
// half (python/granoscope/__init__.py) documents and re-exports it.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"

PYBIND11_MODULE(_granoscope, m) {
  m.doc() = "granoscope compiled module (use the `granoscope` package)";
  gs::py_bind::bind_errors(m);
  gs::py_bind::bind_data(m);
  gs::py_bind::bind_analysis(m);
  gs::py_bind::bind_maps(m);
  gs::py_bind::bind_motion(m);
  gs::py_bind::bind_reports(m);
  gs::py_bind::bind_simulation(m);
  gs::py_bind::bind_dic(m);
}
