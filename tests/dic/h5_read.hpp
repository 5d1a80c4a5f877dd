// Reading back the HDF5 outputs of `granoscope dic`, `render` and the analyses in tests: any
// numeric dataset as doubles with its shape, and root (or object) attributes.
#pragma once

#include <hdf5.h>

#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace gs::test::h5 {

struct Array {
  std::vector<hsize_t> dims;
  std::vector<double> v;
  std::size_t size() const { return v.size(); }
  double operator[](std::size_t i) const { return v[i]; }
};

inline hid_t open_ro(const std::filesystem::path& file) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw std::runtime_error("cannot open " + file.string());
  return f;
}

/// Dataset `name` converted to double (float, integer and uint8 datasets alike).
inline Array read(const std::filesystem::path& file, const std::string& name) {
  const hid_t f = open_ro(file);
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
  if (d < 0) {
    H5Fclose(f);
    throw std::runtime_error(file.string() + ": no dataset " + name);
  }
  const hid_t s = H5Dget_space(d);
  Array a;
  a.dims.resize(static_cast<std::size_t>(H5Sget_simple_extent_ndims(s)));
  H5Sget_simple_extent_dims(s, a.dims.data(), nullptr);
  a.v.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
  const herr_t rc = H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.v.data());
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  if (rc < 0) throw std::runtime_error(file.string() + ": cannot read " + name);
  return a;
}

inline bool has(const std::filesystem::path& file, const std::string& name) {
  const hid_t f = open_ro(file);
  const bool yes = H5Lexists(f, name.c_str(), H5P_DEFAULT) > 0;
  H5Fclose(f);
  return yes;
}

/// String attribute (fixed or variable length) of `object` ("/" = root).
inline std::string attr_string(const std::filesystem::path& file, const std::string& name,
                               const std::string& object = "/") {
  const hid_t f = open_ro(file);
  const hid_t a = H5Aopen_by_name(f, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  if (a < 0) {
    H5Fclose(f);
    throw std::runtime_error(file.string() + ": no attribute " + name);
  }
  const hid_t t = H5Aget_type(a);
  std::string out;
  if (H5Tis_variable_str(t) > 0) {
    const hid_t mt = H5Tcopy(H5T_C_S1);
    H5Tset_size(mt, H5T_VARIABLE);
    char* p = nullptr;
    H5Aread(a, mt, &p);
    out = p ? p : "";
    H5free_memory(p);
    H5Tclose(mt);
  } else {
    const std::size_t n = H5Tget_size(t);
    std::string s(n + 1, '\0');
    const hid_t mt = H5Tcopy(H5T_C_S1);
    H5Tset_size(mt, n + 1);
    H5Aread(a, mt, s.data());
    H5Tclose(mt);
    out = s.c_str();
  }
  H5Tclose(t);
  H5Aclose(a);
  H5Fclose(f);
  return out;
}

/// Numeric scalar attribute as double.
inline double attr_number(const std::filesystem::path& file, const std::string& name,
                          const std::string& object = "/") {
  const hid_t f = open_ro(file);
  const hid_t a = H5Aopen_by_name(f, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  if (a < 0) {
    H5Fclose(f);
    throw std::runtime_error(file.string() + ": no attribute " + name);
  }
  double v = 0.0;
  H5Aread(a, H5T_NATIVE_DOUBLE, &v);
  H5Aclose(a);
  H5Fclose(f);
  return v;
}

}  // namespace gs::test::h5
