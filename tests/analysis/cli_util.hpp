// Helpers of the CLI tests of the analyses: a scratch directory per test, running the
// `granoscope` executable, and reading datasets and attributes of its HDF5 outputs.
#pragma once

#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "../apps/cli_util.hpp"

namespace gs::test {

/// A fresh directory named after the running test (removed by the caller).
inline std::filesystem::path temp_dir(const std::string& prefix) {
  const auto d = std::filesystem::temp_directory_path() /
                 (prefix + "_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// Runs `granoscope ARGS`, stdout and stderr into `log`; returns the exit code.
inline int run(const std::string& args, const std::filesystem::path& log) {
  const std::string cmd = kGranoscope + " " + args + " > " + log.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

/// Whole dataset `name` of an HDF5 file, converted to `type` (e.g. H5T_NATIVE_DOUBLE).
template <class T>
std::vector<T> read_array(const std::filesystem::path& file, const char* name, hid_t type) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0);
  const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  const hid_t s = H5Dget_space(d);
  std::vector<T> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
  H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

inline std::vector<double> read_doubles(const std::filesystem::path& file, const char* name) {
  return read_array<double>(file, name, H5T_NATIVE_DOUBLE);
}

/// A numeric attribute of an object ("/" for the root).
inline double read_attr(const std::filesystem::path& file, const char* object, const char* name) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0);
  const hid_t a = H5Aopen_by_name(f, object, name, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << name;
  double v = 0.0;
  H5Aread(a, H5T_NATIVE_DOUBLE, &v);
  H5Aclose(a);
  H5Fclose(f);
  return v;
}

inline std::string read_format(const std::filesystem::path& file) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t a = H5Aopen(f, "format", H5P_DEFAULT);
  const hid_t t = H5Aget_type(a);
  std::string s(H5Tget_size(t), '\0');
  H5Aread(a, t, s.data());
  H5Tclose(t);
  H5Aclose(a);
  H5Fclose(f);
  return s.c_str();
}

/// Numeric attribute `name="..."` of an XML tag (the text of the tag); NaN when absent.
inline double xml_number(const std::string& tag, const std::string& name) {
  const auto at = tag.find(" " + name + "=\"");
  if (at == std::string::npos) return std::nan("");
  return std::stod(tag.substr(at + name.size() + 3));
}

/// The opening tag of the first element `element` of a VTK XML file (e.g. "Piece").
inline std::string xml_tag(const std::filesystem::path& file, const std::string& element) {
  const std::string s = slurp(file);
  const auto at = s.find("<" + element + " ");
  if (at == std::string::npos) return "";
  return s.substr(at, s.find('>', at) - at + 1);
}

/// RangeMin and RangeMax that VTK's XML writers record for the DataArray `name` of a
/// "PointData" or "CellData" section (for arrays of several components: of their magnitude).
inline std::pair<double, double> vtk_range(const std::filesystem::path& file,
                                           const std::string& section, const std::string& name) {
  const std::string s = slurp(file);
  const auto begin = s.find("<" + section + ">"), end = s.find("</" + section + ">");
  const auto at = s.find("Name=\"" + name + "\"", begin);
  EXPECT_TRUE(begin != std::string::npos && at < end) << file << ": no " << section << " " << name;
  if (begin == std::string::npos || at >= end) return {std::nan(""), std::nan("")};
  const auto open = s.rfind('<', at);
  const std::string tag = s.substr(open, s.find('>', at) - open + 1);
  return {xml_number(tag, "RangeMin"), xml_number(tag, "RangeMax")};
}

}  // namespace gs::test
