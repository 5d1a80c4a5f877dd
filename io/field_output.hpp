// Output of analysis results (fields on points, cells, grids): one HDF5 file of plain arrays with
// a root attribute `format` (what `granoscope figures` dispatches on) and `code_version`, and the
// VTK XML files ParaView opens (.vtu meshes, .vtp polylines, .vti images). Every file is written
// under a temporary name and renamed only when complete (atomic_file.hpp).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace gs {

/// An HDF5 results file. Datasets are written with their full path ("/rev/sigma"); parent groups
/// are created as needed. Nothing appears under the target name until commit().
class H5FieldFile {
 public:
  H5FieldFile(const std::filesystem::path& path, const std::string& format);
  H5FieldFile(const H5FieldFile&) = delete;
  H5FieldFile& operator=(const H5FieldFile&) = delete;
  ~H5FieldFile();

  /// Attributes on the root (`object` = "/") or on an existing group or dataset.
  void attr(const std::string& name, const std::string& value, const std::string& object = "/");
  void attr(const std::string& name, const char* value, const std::string& object = "/") {
    attr(name, std::string(value), object);
  }
  void attr(const std::string& name, double value, const std::string& object = "/");
  void attr(const std::string& name, long long value, const std::string& object = "/");
  void attr(const std::string& name, int value, const std::string& object = "/") {
    attr(name, static_cast<long long>(value), object);
  }
  void group(const std::string& name);

  /// Row-major array of shape `dims` (product = v.size()); empty dims = {v.size()}.
  void write(const std::string& name, const std::vector<double>& v,
             const std::vector<std::size_t>& dims = {});
  void write(const std::string& name, const std::vector<float>& v,
             const std::vector<std::size_t>& dims = {});
  void write(const std::string& name, const std::vector<std::int64_t>& v,
             const std::vector<std::size_t>& dims = {});
  void write(const std::string& name, const std::vector<std::int32_t>& v,
             const std::vector<std::size_t>& dims = {});
  void write(const std::string& name, const std::vector<std::uint8_t>& v,
             const std::vector<std::size_t>& dims = {});
  /// N × 3 array.
  void write(const std::string& name, const std::vector<Eigen::Vector3d>& v);
  /// N × 3 × 3 array (row-major per matrix).
  void write(const std::string& name, const std::vector<Eigen::Matrix3d>& v);

  /// Flushes, closes and renames the file onto its target.
  void commit();
  const std::filesystem::path& target() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A named data array for VTK output: `values.size()` = tuples × components.
struct VtkArray {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

/// Unstructured grid of one cell type (VTK_VERTEX 1, VTK_LINE 3, VTK_TRIANGLE 5, VTK_POLYGON 7,
/// VTK_TETRA 10): `cells[c]` lists the point indices of cell c.
void write_vtu_mesh(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points,
                    int vtk_cell_type, const std::vector<std::vector<std::int64_t>>& cells,
                    const std::vector<VtkArray>& point_data,
                    const std::vector<VtkArray>& cell_data);

/// Polylines (one cell per line, each of at least 2 points) as .vtp.
void write_vtp_polylines(const std::filesystem::path& path,
                         const std::vector<Eigen::Vector3d>& points,
                         const std::vector<std::vector<std::int64_t>>& lines,
                         const std::vector<VtkArray>& point_data,
                         const std::vector<VtkArray>& cell_data);

/// Regular grid as .vti: dims (nx, ny, nz) points, x fastest in the arrays.
void write_vti_image(const std::filesystem::path& path, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& spacing, const std::array<int, 3>& dims,
                     const std::vector<VtkArray>& point_data);

/// CSV table of named columns of equal length (`values.size()` = rows x components); a column of
/// 3 components is written as name_x, name_y, name_z, of 9 as name_xx .. name_zz (row-major),
/// others as name_0, name_1, ... Non-finite values are written as nan.
void write_csv_table(const std::filesystem::path& path, const std::vector<VtkArray>& columns);

/// Row-major values for VtkArray columns and HDF5 datasets: vectors x, y, z in turn; each
/// matrix row by row (a(0, 0), a(0, 1), ...); a dynamic matrix row by row.
std::vector<double> flat_rows(const std::vector<Eigen::Vector3d>& v);
std::vector<double> flat_rows(const std::vector<Eigen::Matrix3d>& m);
std::vector<double> flat_rows(const Eigen::MatrixXd& m);

}  // namespace gs
