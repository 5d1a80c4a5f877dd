// Helpers of the end-to-end CLI tests of the analyses: scratch directory, running the built
// `granoscope` with one log, reading HDF5 outputs back (on top of tests/apps/cli_util.hpp).
#pragma once

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "../apps/cli_util.hpp"

namespace gs::test {

/// A fresh directory named after `prefix`, the process and the running test.
inline std::filesystem::path cli_temp_dir(const std::string& prefix) {
  const auto d = std::filesystem::temp_directory_path() /
                 (prefix + "_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// Runs `granoscope ARGS` with stdout and stderr to `log`; the exit code (-1 if killed).
inline int run_granoscope(const std::string& args, const std::filesystem::path& log) {
  const std::string cmd = kGranoscope + " " + args + " > " + log.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

/// Whole dataset `name` of an HDF5 file, converted to `type` (e.g. H5T_NATIVE_DOUBLE).
template <class T>
std::vector<T> read_h5_array(const std::filesystem::path& file, const char* name, hid_t type) {
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

inline std::vector<double> read_h5_doubles(const std::filesystem::path& file, const char* name) {
  return read_h5_array<double>(file, name, H5T_NATIVE_DOUBLE);
}

/// The root attribute `format` of a granoscope HDF5 output.
inline std::string read_h5_format(const std::filesystem::path& file) {
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

}  // namespace gs::test
