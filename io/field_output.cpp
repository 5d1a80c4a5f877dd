#include "field_output.hpp"

#include <hdf5.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkImageData.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <fstream>
#include <numeric>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "snapshot.hpp"

namespace gs {
namespace {

// Owns one HDF5 handle; a negative id is an error naming the file and the object.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& file, const std::string& what)
      : id_(id), close_(close) {
    if (id < 0) throw InputError(file, "cannot write HDF5 output", what);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { close_(id_); }
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

template <class T>
struct H5Type;
template <>
struct H5Type<double> {
  static hid_t file() { return H5T_IEEE_F64LE; }
  static hid_t mem() { return H5T_NATIVE_DOUBLE; }
};
template <>
struct H5Type<float> {
  static hid_t file() { return H5T_IEEE_F32LE; }
  static hid_t mem() { return H5T_NATIVE_FLOAT; }
};
template <>
struct H5Type<std::int64_t> {
  static hid_t file() { return H5T_STD_I64LE; }
  static hid_t mem() { return H5T_NATIVE_INT64; }
};
template <>
struct H5Type<std::int32_t> {
  static hid_t file() { return H5T_STD_I32LE; }
  static hid_t mem() { return H5T_NATIVE_INT32; }
};
template <>
struct H5Type<std::uint8_t> {
  static hid_t file() { return H5T_STD_U8LE; }
  static hid_t mem() { return H5T_NATIVE_UINT8; }
};

// A large dataset's chunks (first-axis slabs of `chunk_rows` rows) filtered on the threads, then
// written as they are with H5Dwrite_chunk: HDF5 runs its filter pipeline on one thread, and
// deflate was most of `analyze hhd`'s time (0.9 s of 1.5 s at 5.5e4 nodes). Each chunk holds
// what the dataset's declared filters make of it, so any HDF5 reader reads it back: the chunk
// zero-padded to full size (as HDF5 pads an edge chunk), HDF5's byte shuffle (byte j of element
// i at j·elements + i), then zlib at level 1 (the deflate filter's compress2).
template <class T>
void write_filtered_chunks(hid_t ds, const std::vector<T>& v, std::size_t rank,
                           std::size_t chunk_rows, std::size_t row, const std::string& file,
                           const std::string& path) {
  static_assert(std::endian::native == std::endian::little, "the file types are little-endian");
  const std::size_t elems = chunk_rows * row, bytes = elems * sizeof(T);
  const std::size_t chunks = (v.size() + elems - 1) / elems;
  constexpr std::size_t kBatch = 8;  // (compressed on the threads, then written in order)
  std::vector<std::vector<Bytef>> out(kBatch);
  std::vector<uLongf> size(kBatch);
  for (std::size_t b0 = 0; b0 < chunks; b0 += kBatch) {
    const auto nb = static_cast<std::ptrdiff_t>(std::min(kBatch, chunks - b0));
    int failed = 0;
#pragma omp parallel for schedule(dynamic) reduction(+ : failed)
    for (std::ptrdiff_t q = 0; q < nb; ++q) {
      const std::size_t first = (b0 + static_cast<std::size_t>(q)) * elems;
      const std::size_t count = std::min(elems, v.size() - first);
      const auto* src = reinterpret_cast<const unsigned char*>(v.data() + first);
      std::vector<unsigned char> shuffled(bytes, 0);
      for (std::size_t i = 0; i < count; ++i)
        for (std::size_t j = 0; j < sizeof(T); ++j)
          shuffled[j * elems + i] = src[i * sizeof(T) + j];
      auto& o = out[static_cast<std::size_t>(q)];
      uLongf n = compressBound(static_cast<uLong>(bytes));
      o.resize(n);
      failed += compress2(o.data(), &n, shuffled.data(), static_cast<uLong>(bytes), 1) != Z_OK;
      size[static_cast<std::size_t>(q)] = n;
    }
    if (failed) throw InputError(file, "cannot compress HDF5 output", path);
    for (std::ptrdiff_t q = 0; q < nb; ++q) {
      std::vector<hsize_t> offset(rank, 0);
      offset[0] = (b0 + static_cast<std::size_t>(q)) * chunk_rows;
      if (H5Dwrite_chunk(ds, H5P_DEFAULT, 0, offset.data(), size[static_cast<std::size_t>(q)],
                         out[static_cast<std::size_t>(q)].data()) < 0)
        throw InputError(file, "cannot write HDF5 output", path);
    }
  }
}

vtkNew<vtkDoubleArray> to_vtk(const VtkArray& a, std::size_t tuples, const std::string& file) {
  const auto comps = static_cast<std::size_t>(std::max(1, a.components));
  if (a.values.size() != tuples * comps) {
    throw InputError(file, "VTK array " + a.name + " has the wrong length",
                     std::to_string(a.values.size()) + " != " + std::to_string(tuples * comps));
  }
  vtkNew<vtkDoubleArray> v;
  v->SetName(a.name.c_str());
  v->SetNumberOfComponents(static_cast<int>(comps));
  v->SetNumberOfTuples(static_cast<vtkIdType>(tuples));
  for (std::size_t i = 0; i < a.values.size(); ++i)
    v->SetValue(static_cast<vtkIdType>(i), a.values[i]);
  return v;
}

vtkNew<vtkPoints> to_points(const std::vector<Eigen::Vector3d>& points) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(static_cast<vtkIdType>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i)
    pts->SetPoint(static_cast<vtkIdType>(i), points[i].x(), points[i].y(), points[i].z());
  return pts;
}

template <class Writer, class Data>
void write_vtk(const std::filesystem::path& path, Data& data) {
  vtkObject::GlobalWarningDisplayOff();  // VTK's own multi-line report: ours is one line
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  AtomicOutput out(path);
  vtkNew<Writer> w;
  w->SetFileName(out.temp_path().string().c_str());
  w->SetInputData(data);
  w->SetDataModeToBinary();
  // LZ4, not VTK's default zlib: the 3.4e5-tetrahedron HHD mesh in 0.36 s instead of 1.6 s, for
  // 61 MB instead of 54 (ParaView and VTK's readers decompress either; zlib at level 1 took
  // 1.0 s). Inline (base64) data, whose header ranges are exact (appended data's are not).
  w->SetCompressorTypeToLZ4();
  if (w->Write() != 1 || w->GetErrorCode() != 0)
    throw InputError(path.string(), "cannot write VTK output",
                     vtkErrorCode::GetStringFromErrorCode(w->GetErrorCode()));
  out.commit();
}

}  // namespace

struct H5FieldFile::Impl {
  explicit Impl(const std::filesystem::path& path)
      : quiet((H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr), true)),  // our one line, not HDF5's
        out(path),
        name(path.string()),
        file(H5Fcreate(out.temp_path().string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
             H5Fclose, path.string(), "create") {}
  bool quiet;
  AtomicOutput out;
  std::string name;
  Handle file;

  hid_t object(const std::string& path) const {
    return H5Oopen(file.get(), path.c_str(), H5P_DEFAULT);
  }

  void ensure_parents(const std::string& path) {
    for (std::size_t p = path.find('/', 1); p != std::string::npos; p = path.find('/', p + 1)) {
      const std::string g = path.substr(0, p);
      if (H5Lexists(file.get(), g.c_str(), H5P_DEFAULT) <= 0) {
        Handle(H5Gcreate2(file.get(), g.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
               name, g);
      }
    }
  }

  template <class T>
  void write(const std::string& path, const std::vector<T>& v, std::vector<std::size_t> dims) {
    if (dims.empty()) dims = {v.size()};
    const std::size_t n =
        std::accumulate(dims.begin(), dims.end(), std::size_t{1}, std::multiplies<>());
    if (n != v.size()) {
      throw InputError(name, "dataset " + path + " shape does not match its data",
                       std::to_string(n) + " != " + std::to_string(v.size()));
    }
    ensure_parents(path);
    std::vector<hsize_t> hd(dims.begin(), dims.end());
    const Handle space(H5Screate_simple(static_cast<int>(hd.size()), hd.data(), nullptr), H5Sclose,
                       name, path);
    const Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, name, path);
    // Large arrays: chunked (about 1 MiB along the first axis), shuffled and deflated (the
    // shuffle makes doubles compress: 36 MB instead of 40 for the 47 MB of a 5.5e4-node HHD).
    const bool large = n >= 4096;
    const std::size_t row = n / std::max<std::size_t>(1, dims[0]);
    std::vector<hsize_t> chunk(hd);
    if (large) {
      chunk[0] = std::clamp<hsize_t>((1u << 20) / sizeof(T) / std::max<std::size_t>(1, row), 1,
                                     std::max<hsize_t>(1, hd[0]));
      H5Pset_chunk(plist.get(), static_cast<int>(chunk.size()), chunk.data());
      H5Pset_shuffle(plist.get());
      H5Pset_deflate(plist.get(), 1);
    }
    const Handle ds(H5Dcreate2(file.get(), path.c_str(), H5Type<T>::file(), space.get(),
                               H5P_DEFAULT, plist.get(), H5P_DEFAULT),
                    H5Dclose, name, path);
    if (large) {
      write_filtered_chunks(ds.get(), v, hd.size(), static_cast<std::size_t>(chunk[0]), row, name,
                            path);
    } else if (n > 0 &&
               H5Dwrite(ds.get(), H5Type<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0) {
      throw InputError(name, "cannot write HDF5 output", path);
    }
  }

  void attr(const std::string& attr_name, hid_t file_type, hid_t mem_type, const void* value,
            const std::string& obj_path) {
    const Handle obj(object(obj_path), H5Oclose, name, obj_path);
    if (H5Aexists(obj.get(), attr_name.c_str()) > 0) H5Adelete(obj.get(), attr_name.c_str());
    const Handle space(H5Screate(H5S_SCALAR), H5Sclose, name, attr_name);
    const Handle a(
        H5Acreate2(obj.get(), attr_name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose, name, attr_name);
    if (H5Awrite(a.get(), mem_type, value) < 0)
      throw InputError(name, "cannot write HDF5 output", attr_name);
  }
};

H5FieldFile::H5FieldFile(const std::filesystem::path& path, const std::string& format)
    : impl_(std::make_unique<Impl>(path)) {
  attr("format", format);
  attr("code_version", code_version());
}

H5FieldFile::~H5FieldFile() = default;

void H5FieldFile::attr(const std::string& name, const std::string& value,
                       const std::string& object) {
  const Handle type(H5Tcopy(H5T_C_S1), H5Tclose, impl_->name, name);
  H5Tset_size(type.get(), std::max<std::size_t>(1, value.size()));
  H5Tset_strpad(type.get(), H5T_STR_NULLTERM);
  const std::string buf = value.empty() ? std::string(1, '\0') : value;
  impl_->attr(name, type.get(), type.get(), buf.data(), object);
}

void H5FieldFile::attr(const std::string& name, double value, const std::string& object) {
  impl_->attr(name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value, object);
}

void H5FieldFile::attr(const std::string& name, long long value, const std::string& object) {
  impl_->attr(name, H5T_STD_I64LE, H5T_NATIVE_LLONG, &value, object);
}

void H5FieldFile::group(const std::string& name) {
  impl_->ensure_parents(name + "/");
}

void H5FieldFile::write(const std::string& name, const std::vector<double>& v,
                        const std::vector<std::size_t>& dims) {
  impl_->write(name, v, dims);
}
void H5FieldFile::write(const std::string& name, const std::vector<float>& v,
                        const std::vector<std::size_t>& dims) {
  impl_->write(name, v, dims);
}
void H5FieldFile::write(const std::string& name, const std::vector<std::int64_t>& v,
                        const std::vector<std::size_t>& dims) {
  impl_->write(name, v, dims);
}
void H5FieldFile::write(const std::string& name, const std::vector<std::int32_t>& v,
                        const std::vector<std::size_t>& dims) {
  impl_->write(name, v, dims);
}
void H5FieldFile::write(const std::string& name, const std::vector<std::uint8_t>& v,
                        const std::vector<std::size_t>& dims) {
  impl_->write(name, v, dims);
}

void H5FieldFile::write(const std::string& name, const std::vector<Eigen::Vector3d>& v) {
  std::vector<double> flat;
  flat.reserve(3 * v.size());
  for (const auto& x : v) flat.insert(flat.end(), {x.x(), x.y(), x.z()});
  impl_->write(name, flat, {v.size(), 3});
}

void H5FieldFile::write(const std::string& name, const std::vector<Eigen::Matrix3d>& v) {
  std::vector<double> flat;
  flat.reserve(9 * v.size());
  for (const auto& m : v)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) flat.push_back(m(i, j));
  impl_->write(name, flat, {v.size(), 3, 3});
}

void H5FieldFile::commit() {
  if (H5Fflush(impl_->file.get(), H5F_SCOPE_GLOBAL) < 0)
    throw InputError(impl_->name, "cannot write HDF5 output", "flush");
  impl_->out.commit();
}

const std::filesystem::path& H5FieldFile::target() const {
  return impl_->out.target();
}

void write_vtu_mesh(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points,
                    int vtk_cell_type, const std::vector<std::vector<std::int64_t>>& cells,
                    const std::vector<VtkArray>& point_data,
                    const std::vector<VtkArray>& cell_data) {
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(to_points(points));
  grid->Allocate(static_cast<vtkIdType>(cells.size()));
  std::vector<vtkIdType> ids;
  for (const auto& c : cells) {
    ids.assign(c.begin(), c.end());
    for (const auto id : ids) {
      if (id < 0 || id >= static_cast<vtkIdType>(points.size()))
        throw InputError(path.string(), "VTU cell refers to a missing point", std::to_string(id));
    }
    grid->InsertNextCell(vtk_cell_type, static_cast<vtkIdType>(ids.size()), ids.data());
  }
  for (const auto& a : point_data)
    grid->GetPointData()->AddArray(to_vtk(a, points.size(), path.string()));
  for (const auto& a : cell_data)
    grid->GetCellData()->AddArray(to_vtk(a, cells.size(), path.string()));
  write_vtk<vtkXMLUnstructuredGridWriter>(path, grid);
}

void write_vtp_polylines(const std::filesystem::path& path,
                         const std::vector<Eigen::Vector3d>& points,
                         const std::vector<std::vector<std::int64_t>>& lines,
                         const std::vector<VtkArray>& point_data,
                         const std::vector<VtkArray>& cell_data) {
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(to_points(points));
  vtkNew<vtkCellArray> cells;
  std::vector<vtkIdType> ids;
  for (const auto& l : lines) {
    if (l.size() < 2) {  // VTK rejects (and may crash on) one-point lines
      throw InputError(path.string(), "VTP line with fewer than 2 points",
                       std::to_string(l.size()));
    }
    ids.assign(l.begin(), l.end());
    for (const auto id : ids) {
      if (id < 0 || id >= static_cast<vtkIdType>(points.size()))
        throw InputError(path.string(), "VTP line refers to a missing point", std::to_string(id));
    }
    cells->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  poly->SetLines(cells);
  for (const auto& a : point_data)
    poly->GetPointData()->AddArray(to_vtk(a, points.size(), path.string()));
  for (const auto& a : cell_data)
    poly->GetCellData()->AddArray(to_vtk(a, lines.size(), path.string()));
  write_vtk<vtkXMLPolyDataWriter>(path, poly);
}

void write_vti_image(const std::filesystem::path& path, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& spacing, const std::array<int, 3>& dims,
                     const std::vector<VtkArray>& point_data) {
  vtkNew<vtkImageData> img;
  img->SetDimensions(dims[0], dims[1], dims[2]);
  img->SetOrigin(origin.x(), origin.y(), origin.z());
  img->SetSpacing(spacing.x(), spacing.y(), spacing.z());
  const auto n = static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) *
                 static_cast<std::size_t>(dims[2]);
  for (const auto& a : point_data) img->GetPointData()->AddArray(to_vtk(a, n, path.string()));
  write_vtk<vtkXMLImageDataWriter>(path, img);
}

void write_csv_table(const std::filesystem::path& path, const std::vector<VtkArray>& columns) {
  std::size_t rows = 0;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const auto& c = columns[k];
    if (c.components < 1 || c.values.size() % static_cast<std::size_t>(c.components) != 0)
      throw InputError(path.string(), "CSV column has a bad size", c.name);
    const std::size_t n = c.values.size() / static_cast<std::size_t>(c.components);
    if (k > 0 && n != rows) throw InputError(path.string(), "CSV columns differ in length", c.name);
    rows = n;
  }
  AtomicOutput out(path);
  {
    std::ofstream os(out.temp_path());
    if (!os) throw InputError(path.string(), "cannot write CSV");
    static const char* xyz[3] = {"x", "y", "z"};
    bool first = true;
    for (const auto& c : columns)
      for (int j = 0; j < c.components; ++j) {
        os << (first ? "" : ",") << c.name;
        first = false;
        if (c.components == 3) os << '_' << xyz[j];
        if (c.components == 9) os << '_' << xyz[j / 3] << xyz[j % 3];
        if (c.components != 1 && c.components != 3 && c.components != 9) os << '_' << j;
      }
    os << '\n';
    os.precision(12);
    for (std::size_t r = 0; r < rows; ++r) {
      first = true;
      for (const auto& c : columns)
        for (int j = 0; j < c.components; ++j) {
          const double v =
              c.values[r * static_cast<std::size_t>(c.components) + static_cast<std::size_t>(j)];
          os << (first ? "" : ",");
          first = false;
          if (std::isfinite(v)) {
            os << v;
          } else {
            os << "nan";
          }
        }
      os << '\n';
    }
    os.flush();
    if (!os) throw InputError(path.string(), "cannot write CSV");
  }
  out.commit();
}

std::vector<double> flat_rows(const std::vector<Eigen::Vector3d>& v) {
  std::vector<double> out;
  out.reserve(3 * v.size());
  for (const auto& x : v) out.insert(out.end(), {x.x(), x.y(), x.z()});
  return out;
}

std::vector<double> flat_rows(const std::vector<Eigen::Matrix3d>& m) {
  std::vector<double> out;
  out.reserve(9 * m.size());
  for (const auto& a : m)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out.push_back(a(i, j));
  return out;
}

std::vector<double> flat_rows(const Eigen::MatrixXd& m) {
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(m.size()));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) out.push_back(m(i, j));
  return out;
}

}  // namespace gs
