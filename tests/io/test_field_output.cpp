// H5FieldFile (io/field_output.hpp): large arrays are chunked, shuffled and deflated, their
// chunks filtered on the threads and written directly; HDF5 reads back every value exactly,
// edge chunks included, for each element type. The VTK meshes (LZ4) read back exactly too.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "field_output.hpp"

namespace {

namespace fs = std::filesystem;

template <class T>
std::vector<T> read_back(hid_t file, const std::string& path, hid_t mem_type,
                         std::vector<hsize_t>& dims, int& filters) {
  const hid_t ds = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(ds, 0) << path;
  const hid_t space = H5Dget_space(ds);
  dims.assign(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)), 0);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  hsize_t n = 1;
  for (const auto d : dims) n *= d;
  std::vector<T> v(static_cast<std::size_t>(n));
  EXPECT_GE(H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << path;
  const hid_t dcpl = H5Dget_create_plist(ds);
  filters = H5Pget_nfilters(dcpl);
  if (filters == 2) {  // (shuffle, then deflate)
    unsigned flags = 0;
    std::size_t nelem = 0;
    char name[64];
    unsigned config = 0;
    EXPECT_EQ(H5Pget_filter2(dcpl, 0, &flags, &nelem, nullptr, sizeof name, name, &config),
              H5Z_FILTER_SHUFFLE);
    nelem = 1;
    unsigned level = 0;
    EXPECT_EQ(H5Pget_filter2(dcpl, 1, &flags, &nelem, &level, sizeof name, name, &config),
              H5Z_FILTER_DEFLATE);
    EXPECT_EQ(level, 1u);
  }
  H5Pclose(dcpl);
  H5Sclose(space);
  H5Dclose(ds);
  return v;
}

TEST(FieldOutput, LargeArraysChunkedShuffledDeflatedAndReadBackExactly) {
  const fs::path path = fs::temp_directory_path() / "gs_field_output_test.h5";
  // 100 003 rows of three doubles: 3 chunks of 43 690 rows, the last one partial; int32 rows of
  // four; bytes; a small array (contiguous, unfiltered); and values whose bytes all differ.
  std::vector<double> d(3 * 100003);
  for (std::size_t i = 0; i < d.size(); ++i)
    d[i] = 1.0 / (1.0 + static_cast<double>(i)) - 1e-3 * static_cast<double>(i % 7);
  std::vector<std::int32_t> k(4 * 70001);
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::int32_t>(i * 2654435761u);
  std::vector<std::int64_t> id(50001);
  for (std::size_t i = 0; i < id.size(); ++i) id[i] = -static_cast<std::int64_t>(i) << 20;
  std::vector<std::uint8_t> b(300007);
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(i * 31 % 251);
  std::vector<float> f(9000);
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = static_cast<float>(i) * 0.37f;
  const std::vector<double> small = {1.0, -2.5, 3.25};
  {
    gs::H5FieldFile out(path, "test");
    out.write("/a/d", d, {100003, 3});
    out.write("/a/k", k, {70001, 4});
    out.write("/id", id);
    out.write("/b", b);
    out.write("/f", f);
    out.write("/small", small);
    out.commit();
  }
  const hid_t file = H5Fopen(path.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  std::vector<hsize_t> dims;
  int filters = 0;
  EXPECT_EQ(read_back<double>(file, "/a/d", H5T_NATIVE_DOUBLE, dims, filters), d);
  EXPECT_EQ(dims, (std::vector<hsize_t>{100003, 3}));
  EXPECT_EQ(filters, 2);
  EXPECT_EQ(read_back<std::int32_t>(file, "/a/k", H5T_NATIVE_INT32, dims, filters), k);
  EXPECT_EQ(dims, (std::vector<hsize_t>{70001, 4}));
  EXPECT_EQ(filters, 2);
  EXPECT_EQ(read_back<std::int64_t>(file, "/id", H5T_NATIVE_INT64, dims, filters), id);
  EXPECT_EQ(filters, 2);
  EXPECT_EQ(read_back<std::uint8_t>(file, "/b", H5T_NATIVE_UINT8, dims, filters), b);
  EXPECT_EQ(filters, 2);
  EXPECT_EQ(read_back<float>(file, "/f", H5T_NATIVE_FLOAT, dims, filters), f);
  EXPECT_EQ(filters, 2);
  EXPECT_EQ(read_back<double>(file, "/small", H5T_NATIVE_DOUBLE, dims, filters), small);
  EXPECT_EQ(filters, 0);
  H5Fclose(file);
  fs::remove(path);
}

TEST(FieldOutput, VtuMeshReadBackExactlyByVtk) {
  // 20 000 tetrahedra of a strip of points: point and cell arrays of several components, in
  // LZ4-compressed inline blocks, read back by VTK's own reader bit for bit.
  const fs::path path = fs::temp_directory_path() / "gs_field_output_test.vtu";
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 20003; ++i)
    points.emplace_back(0.001 * i, std::sin(0.1 * i), std::cos(0.37 * i));
  std::vector<std::vector<std::int64_t>> cells;
  for (std::int64_t i = 0; i + 3 < static_cast<std::int64_t>(points.size()); ++i)
    cells.push_back({i, i + 1, i + 2, i + 3});
  gs::VtkArray u{"u", 1, {}}, g{"grad_u", 3, {}};
  for (std::size_t i = 0; i < points.size(); ++i) u.values.push_back(1.0 / (3.0 + i));
  for (std::size_t k = 0; k < cells.size(); ++k)
    for (int c = 0; c < 3; ++c) g.values.push_back(std::exp(-1e-4 * k) * (c + 0.1));
  gs::write_vtu_mesh(path, points, 10, cells, {u}, {g});
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.string().c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_EQ(grid->GetNumberOfPoints(), static_cast<vtkIdType>(points.size()));
  ASSERT_EQ(grid->GetNumberOfCells(), static_cast<vtkIdType>(cells.size()));
  vtkDataArray* ru = grid->GetPointData()->GetArray("u");
  vtkDataArray* rg = grid->GetCellData()->GetArray("grad_u");
  ASSERT_NE(ru, nullptr);
  ASSERT_NE(rg, nullptr);
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(ru->GetComponent(static_cast<vtkIdType>(i), 0), u.values[i]);
    double x[3];
    grid->GetPoint(static_cast<vtkIdType>(i), x);
    ASSERT_EQ(x[1], points[i].y());
  }
  for (std::size_t k = 0; k < cells.size(); ++k)
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(rg->GetComponent(static_cast<vtkIdType>(k), c), g.values[3 * k + c]);
  fs::remove(path);
}

}  // namespace
