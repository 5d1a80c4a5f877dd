// gs::InputError -> granoscope.Error(ValueError): str(e) is the CLI's line without "error: ".
#include <pybind11/pybind11.h>

#include <stdexcept>

#include "bindings.hpp"
#include "errors.hpp"

namespace py = pybind11;

namespace gs::py_bind {

void bind_errors(py::module_& m) {
  static py::exception<InputError> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      error(e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
}

}  // namespace gs::py_bind
