#include "dic_io.hpp"

#include <hdf5.h>
#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "render_frames.hpp"
#include "snapshot.hpp"

namespace gs::dic {
namespace {

class H5 {
 public:
  H5(hid_t id, herr_t (*close)(hid_t), const std::string& file, const char* what)
      : id_(id), close_(close) {
    if (id < 0) throw InputError(file, "HDF5 error", what);
  }
  H5(const H5&) = delete;
  H5& operator=(const H5&) = delete;
  ~H5() { close_(id_); }
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void attr_string(hid_t obj, const std::string& file, const char* name, const std::string& value) {
  const H5 type(H5Tcopy(H5T_C_S1), H5Tclose, file, name);
  H5Tset_size(type.get(), std::max<std::size_t>(1, value.size()));
  H5Tset_strpad(type.get(), H5T_STR_NULLTERM);
  const H5 space(H5Screate(H5S_SCALAR), H5Sclose, file, name);
  const H5 attr(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
                file, name);
  if (H5Awrite(attr.get(), type.get(), value.c_str()) < 0)
    throw InputError(file, "HDF5 write", name);
}

void attr_double(hid_t obj, const std::string& file, const char* name, double value) {
  const H5 space(H5Screate(H5S_SCALAR), H5Sclose, file, name);
  const H5 attr(H5Acreate2(obj, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose, file, name);
  if (H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, &value) < 0)
    throw InputError(file, "HDF5 write", name);
}

void attr_int(hid_t obj, const std::string& file, const char* name, long long value) {
  const H5 space(H5Screate(H5S_SCALAR), H5Sclose, file, name);
  const H5 attr(H5Acreate2(obj, name, H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose, file, name);
  if (H5Awrite(attr.get(), H5T_NATIVE_LLONG, &value) < 0)
    throw InputError(file, "HDF5 write", name);
}

template <class T>
void dataset(hid_t file_id, const std::string& file, const char* name,
             const std::vector<hsize_t>& dims, hid_t file_type, hid_t mem_type,
             const std::vector<T>& data) {
  const H5 space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose,
                 file, name);
  const H5 ds(
      H5Dcreate2(file_id, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose, file, name);
  if (H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    throw InputError(file, "HDF5 write", name);
}

using Getter = std::function<const std::vector<double>&(const FrameResult&)>;

struct Column {
  const char* name;
  Getter get;
};

std::vector<Column> strain_columns(bool small) {
  if (small)
    return {
        {"exx", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.sxx; }},
        {"eyy", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.syy; }},
        {"exy", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.sxy; }}};
  return {{"exx", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.exx; }},
          {"eyy", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.eyy; }},
          {"exy", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.exy; }}};
}

}  // namespace

void write_dic_hdf5(const std::filesystem::path& path, const SequenceResult& result,
                    const DicRunInfo& info) {
  AtomicOutput out(path);
  const std::string name = path.string();
  {
    const H5 file(
        H5Fcreate(out.temp_path().string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
        H5Fclose, name, "create");
    const hid_t root = file.get();
    attr_string(root, name, "format", kDicFormatName);
    attr_int(root, name, "schema_version", 1);
    attr_string(root, name, "code_version", code_version());
    attr_int(root, name, "subset_px", info.subset_px);
    attr_int(root, name, "step_px", info.step_px);
    attr_int(root, name, "strain_window_points", info.strain_window_points);
    attr_double(root, name, "vsg_px", info.vsg_px);
    attr_string(root, name, "mode", info.incremental ? "incremental" : "cumulative");
    attr_string(root, name, "strain_csv_vtk", info.small_strain ? "small" : "green-lagrange");
    attr_int(root, name, "image_rows", info.image_rows);
    attr_int(root, name, "image_cols", info.image_cols);
    std::string images;
    for (const auto& s : info.images) images += (images.empty() ? "" : "\n") + s;
    attr_string(root, name, "images", images);
    const PoiGrid& g = result.grid;
    std::vector<double> xs(static_cast<std::size_t>(g.nx)), ys(static_cast<std::size_t>(g.ny));
    for (int i = 0; i < g.nx; ++i) xs[static_cast<std::size_t>(i)] = g.x0 + i * g.step;
    for (int j = 0; j < g.ny; ++j) ys[static_cast<std::size_t>(j)] = g.y0 + j * g.step;
    dataset(root, name, "x", {static_cast<hsize_t>(g.nx)}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, xs);
    dataset(root, name, "y", {static_cast<hsize_t>(g.ny)}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, ys);
    std::vector<std::uint8_t> roi(g.in_roi);
    dataset(root, name, "roi", {static_cast<hsize_t>(g.ny), static_cast<hsize_t>(g.nx)},
            H5T_STD_U8LE, H5T_NATIVE_UINT8, roi);
    const std::vector<hsize_t> dims{static_cast<hsize_t>(result.frames.size()),
                                    static_cast<hsize_t>(g.ny), static_cast<hsize_t>(g.nx)};
    const std::vector<Column> cols{
        {"u", [](const FrameResult& f) -> const std::vector<double>& { return f.u; }},
        {"v", [](const FrameResult& f) -> const std::vector<double>& { return f.v; }},
        {"zncc", [](const FrameResult& f) -> const std::vector<double>& { return f.zncc; }},
        {"exx", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.exx; }},
        {"eyy", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.eyy; }},
        {"exy", [](const FrameResult& f) -> const std::vector<double>& { return f.strain.exy; }},
        {"exx_small",
         [](const FrameResult& f) -> const std::vector<double>& { return f.strain.sxx; }},
        {"eyy_small",
         [](const FrameResult& f) -> const std::vector<double>& { return f.strain.syy; }},
        {"exy_small",
         [](const FrameResult& f) -> const std::vector<double>& { return f.strain.sxy; }}};
    for (const auto& c : cols) {
      std::vector<double> all;
      for (const auto& f : result.frames) all.insert(all.end(), c.get(f).begin(), c.get(f).end());
      dataset(root, name, c.name, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, all);
    }
    std::vector<std::uint8_t> valid;
    for (const auto& f : result.frames) valid.insert(valid.end(), f.valid.begin(), f.valid.end());
    dataset(root, name, "valid", dims, H5T_STD_U8LE, H5T_NATIVE_UINT8, valid);
  }
  out.commit();
}

void write_dic_csv(const std::filesystem::path& path, const SequenceResult& result,
                   std::size_t frame, const DicRunInfo& info) {
  AtomicOutput out(path);
  {
    std::ofstream os(out.temp_path());
    if (!os) throw InputError(path.string(), "cannot write CSV");
    const FrameResult& f = result.frames.at(frame);
    const auto strain = strain_columns(info.small_strain);
    os << "x,y,u,v,exx,eyy,exy,zncc,valid\n" << std::setprecision(10);
    for (int i = 0; i < result.grid.size(); ++i) {
      const auto c = static_cast<std::size_t>(i);
      os << result.grid.x(i) << ',' << result.grid.y(i) << ',' << f.u[c] << ',' << f.v[c] << ','
         << strain[0].get(f)[c] << ',' << strain[1].get(f)[c] << ',' << strain[2].get(f)[c] << ','
         << f.zncc[c] << ',' << static_cast<int>(f.valid[c]) << '\n';
    }
    os.flush();
    if (!os) throw InputError(path.string(), "cannot write CSV");
  }
  out.commit();
}

void write_dic_vti(const std::filesystem::path& path, const SequenceResult& result,
                   std::size_t frame, const DicRunInfo& info) {
  AtomicOutput out(path);
  const PoiGrid& g = result.grid;
  const FrameResult& f = result.frames.at(frame);
  vtkNew<vtkImageData> img;
  img->SetDimensions(g.nx, g.ny, 1);
  img->SetOrigin(g.x0, g.y0, 0.0);
  img->SetSpacing(g.step, g.step, 1.0);
  auto add = [&](const char* name, const std::vector<double>& values) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i)
      a->SetValue(static_cast<vtkIdType>(i), values[i]);
    img->GetPointData()->AddArray(a);
  };
  add("u", f.u);
  add("v", f.v);
  for (const auto& c : strain_columns(info.small_strain)) add(c.name, c.get(f));
  add("zncc", f.zncc);
  vtkNew<vtkUnsignedCharArray> valid;
  valid->SetName("valid");
  valid->SetNumberOfValues(static_cast<vtkIdType>(f.valid.size()));
  for (std::size_t i = 0; i < f.valid.size(); ++i)
    valid->SetValue(static_cast<vtkIdType>(i), f.valid[i]);
  img->GetPointData()->AddArray(valid);
  vtkNew<vtkXMLImageDataWriter> w;
  w->SetFileName(out.temp_path().string().c_str());
  w->SetInputData(img);
  if (w->Write() != 1) throw InputError(path.string(), "cannot write VTK image");
  out.commit();
}

void write_ground_truth_hdf5(const std::filesystem::path& path, const Camera& camera,
                             const std::string& view, const std::vector<GroundTruth>& frames) {
  AtomicOutput out(path);
  const std::string name = path.string();
  {
    const H5 file(
        H5Fcreate(out.temp_path().string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
        H5Fclose, name, "create");
    const hid_t root = file.get();
    attr_string(root, name, "format", "granoscope-render-truth");
    attr_string(root, name, "code_version", code_version());
    attr_string(root, name, "view", view);
    attr_double(root, name, "px_per_m", camera.px_per_m);
    attr_double(root, name, "a0_m", camera.a0);
    attr_double(root, name, "b0_m", camera.b0);
    attr_string(root, name, "reference",
                "frame 0 of the input; u, v in px, image axes (x right, y down)");
    const auto rows = static_cast<hsize_t>(camera.rows), cols = static_cast<hsize_t>(camera.cols);
    const auto nf = static_cast<hsize_t>(frames.size());
    std::vector<int> grain;
    if (!frames.empty()) {
      const cv::Mat& g = frames.front().grain;
      grain.assign(g.begin<int>(), g.end<int>());
    }
    dataset(root, name, "grain", {rows, cols}, H5T_STD_I32LE, H5T_NATIVE_INT, grain);
    std::vector<float> u, v;
    std::vector<std::uint8_t> vis;
    for (const auto& f : frames) {
      for (auto it = f.u.begin<double>(); it != f.u.end<double>(); ++it)
        u.push_back(static_cast<float>(*it));
      for (auto it = f.v.begin<double>(); it != f.v.end<double>(); ++it)
        v.push_back(static_cast<float>(*it));
      vis.insert(vis.end(), f.visible.begin<std::uint8_t>(), f.visible.end<std::uint8_t>());
    }
    dataset(root, name, "u", {nf, rows, cols}, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, u);
    dataset(root, name, "v", {nf, rows, cols}, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, v);
    dataset(root, name, "visible", {nf, rows, cols}, H5T_STD_U8LE, H5T_NATIVE_UINT8, vis);
  }
  out.commit();
}

}  // namespace gs::dic
