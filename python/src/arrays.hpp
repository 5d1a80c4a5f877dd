// numpy arrays from the libraries' result types (copies: results are owned by Python after the
// call), shared by the analysis bindings.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "field_output.hpp"

namespace gs::py_bind {

namespace py = pybind11;

/// (n,) array of a vector.
template <class T>
py::array_t<T> array1(const std::vector<T>& v) {
  py::array_t<T> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

/// (n, cols) array of row-major values.
template <class T>
py::array_t<T> array2(const std::vector<T>& v, std::size_t cols) {
  const auto n = static_cast<py::ssize_t>(cols > 0 ? v.size() / cols : 0);
  py::array_t<T> out({n, static_cast<py::ssize_t>(cols)});
  std::copy(v.begin(), v.begin() + n * static_cast<py::ssize_t>(cols), out.mutable_data());
  return out;
}

/// (n, 3) array of 3-vectors.
inline py::array_t<double> rows3(const std::vector<Eigen::Vector3d>& v) {
  py::array_t<double> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  double* p = out.mutable_data();
  for (const auto& x : v) p = std::copy(x.data(), x.data() + 3, p);
  return out;
}

/// (n, 2) array of 2-vectors.
inline py::array_t<double> rows2(const std::vector<Eigen::Vector2d>& v) {
  py::array_t<double> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{2}});
  double* p = out.mutable_data();
  for (const auto& x : v) p = std::copy(x.data(), x.data() + 2, p);
  return out;
}

/// (n, 3, 3) array of 3x3 matrices, [k, i, j] = m_k(i, j).
inline py::array_t<double> mats3(const std::vector<Eigen::Matrix3d>& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.size()), py::ssize_t{3}, py::ssize_t{3}});
  double* p = out.mutable_data();
  for (const auto& a : m)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) *p++ = a(i, j);
  return out;
}

/// A column of a table: 1 component (n,), 3 (n, 3), 9 (n, 3, 3), else (n, components).
inline py::array_t<double> column(const VtkArray& a) {
  const auto c = static_cast<std::size_t>(a.components);
  const auto n = static_cast<py::ssize_t>(c > 0 ? a.values.size() / c : 0);
  py::array_t<double> out = c == 1   ? py::array_t<double>(n)
                            : c == 9 ? py::array_t<double>({n, py::ssize_t{3}, py::ssize_t{3}})
                                     : py::array_t<double>({n, static_cast<py::ssize_t>(c)});
  std::copy(a.values.begin(), a.values.end(), out.mutable_data());
  return out;
}

/// Columns by name, in order.
inline py::dict table(const std::vector<VtkArray>& cols) {
  py::dict d;
  for (const auto& c : cols) d[py::str(c.name)] = column(c);
  return d;
}

}  // namespace gs::py_bind
