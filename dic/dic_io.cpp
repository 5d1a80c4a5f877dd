#include "dic_io.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "render_frames.hpp"
#include "snapshot.hpp"

namespace gs::dic {
namespace {

using Column = DicColumn;

// exx, eyy, exy of the CSV and VTK outputs (named so in both modes): Green–Lagrange, or small
// strain with --strain small.
std::vector<Column> strain_columns(bool small) {
  const auto& c = dic_columns();
  const std::size_t first = small ? 6 : 3;
  return {{"exx", c[first].get}, {"eyy", c[first + 1].get}, {"exy", c[first + 2].get}};
}

}  // namespace

const std::vector<DicColumn>& dic_columns() {
  using F = FrameResult;
  using V = std::vector<double>;
  static const std::vector<DicColumn> columns{
      {"u", [](const F& f) -> const V& { return f.u; }},
      {"v", [](const F& f) -> const V& { return f.v; }},
      {"zncc", [](const F& f) -> const V& { return f.zncc; }},
      {"exx", [](const F& f) -> const V& { return f.strain.exx; }},
      {"eyy", [](const F& f) -> const V& { return f.strain.eyy; }},
      {"exy", [](const F& f) -> const V& { return f.strain.exy; }},
      {"exx_small", [](const F& f) -> const V& { return f.strain.sxx; }},
      {"eyy_small", [](const F& f) -> const V& { return f.strain.syy; }},
      {"exy_small", [](const F& f) -> const V& { return f.strain.sxy; }}};
  return columns;
}

std::vector<double> grid_x(const PoiGrid& g) {
  std::vector<double> x(static_cast<std::size_t>(g.nx));
  for (int i = 0; i < g.nx; ++i) x[static_cast<std::size_t>(i)] = g.x0 + i * g.step;
  return x;
}

std::vector<double> grid_y(const PoiGrid& g) {
  std::vector<double> y(static_cast<std::size_t>(g.ny));
  for (int j = 0; j < g.ny; ++j) y[static_cast<std::size_t>(j)] = g.y0 + j * g.step;
  return y;
}

void write_dic_hdf5(const std::filesystem::path& path, const SequenceResult& result,
                    const DicRunInfo& info) {
  H5FieldFile h(path, kDicFormatName);
  h.attr("schema_version", 1);
  h.attr("subset_px", info.subset_px);
  h.attr("step_px", info.step_px);
  h.attr("shape_function", info.shape_function);
  h.attr("strain_window_points", info.strain_window_points);
  h.attr("vsg_px", info.vsg_px);
  h.attr("mode", info.incremental ? "incremental" : "cumulative");
  h.attr("strain_csv_vtk", info.small_strain ? "small" : "green-lagrange");
  h.attr("image_rows", info.image_rows);
  h.attr("image_cols", info.image_cols);
  std::string images;
  for (const auto& s : info.images) images += (images.empty() ? "" : "\n") + s;
  h.attr("images", images);
  const PoiGrid& g = result.grid;
  h.write("/x", grid_x(g));
  h.write("/y", grid_y(g));
  const auto ny = static_cast<std::size_t>(g.ny), nx = static_cast<std::size_t>(g.nx);
  h.write("/roi", std::vector<std::uint8_t>(g.in_roi), {ny, nx});
  const std::vector<std::size_t> dims{result.frames.size(), ny, nx};
  for (const auto& c : dic_columns()) {
    std::vector<double> all;
    for (const auto& f : result.frames) all.insert(all.end(), c.get(f).begin(), c.get(f).end());
    h.write(std::string("/") + c.name, all, dims);
  }
  std::vector<std::uint8_t> valid;
  for (const auto& f : result.frames) valid.insert(valid.end(), f.valid.begin(), f.valid.end());
  h.write("/valid", valid, dims);
  h.commit();
}

namespace {

// printf's %.10g (what std::setprecision(10) gives), through std::to_chars: several times faster
// than the stream.
void put(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 10);
  out.append(buf, r.ptr);
}
void put(std::string& out, int v) {
  char buf[16];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

}  // namespace

void write_dic_csv(const std::filesystem::path& path, const SequenceResult& result,
                   std::size_t frame, const DicRunInfo& info) {
  AtomicOutput out(path);
  {
    std::ofstream os(out.temp_path(), std::ios::binary);
    if (!os) throw InputError(path.string(), "cannot write CSV");
    const FrameResult& f = result.frames.at(frame);
    const auto strain = strain_columns(info.small_strain);
    const std::vector<double>* columns[] = {
        &f.u, &f.v, &strain[0].get(f), &strain[1].get(f), &strain[2].get(f), &f.zncc};
    std::string text = "x,y,u,v,exx,eyy,exy,zncc,valid\n";
    const int n = result.grid.size();
    for (int i = 0; i < n; ++i) {
      const auto c = static_cast<std::size_t>(i);
      put(text, result.grid.x(i));
      text += ',';
      put(text, result.grid.y(i));
      for (const auto* col : columns) {
        text += ',';
        put(text, (*col)[c]);
      }
      text += ',';
      text += f.valid[c] ? '1' : '0';
      text += '\n';
      if (text.size() > (1u << 20) || i + 1 == n) {
        os.write(text.data(), static_cast<std::streamsize>(text.size()));
        text.clear();
      }
    }
    os.flush();
    if (!os) throw InputError(path.string(), "cannot write CSV");
  }
  out.commit();
}

void write_dic_vti(const std::filesystem::path& path, const SequenceResult& result,
                   std::size_t frame, const DicRunInfo& info) {
  const PoiGrid& g = result.grid;
  const FrameResult& f = result.frames.at(frame);
  std::vector<VtkArray> arrays{{"u", 1, f.u}, {"v", 1, f.v}};
  for (const auto& c : strain_columns(info.small_strain)) arrays.push_back({c.name, 1, c.get(f)});
  arrays.push_back({"zncc", 1, f.zncc});
  arrays.push_back({"valid", 1, std::vector<double>(f.valid.begin(), f.valid.end())});
  write_vti_image(path, Eigen::Vector3d(g.x0, g.y0, 0.0), Eigen::Vector3d(g.step, g.step, 1.0),
                  {g.nx, g.ny, 1}, arrays);
}

std::filesystem::path frame_output_path(const std::filesystem::path& h5, std::size_t frame,
                                        const std::string& extension) {
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "_%04zu", frame + 1);
  return h5.parent_path() / (h5.stem().string() + suffix + extension);
}

void write_dic_outputs(const std::filesystem::path& h5, const SequenceResult& result,
                       const DicRunInfo& info, bool csv, bool vtk, int threads) {
  // Tasks, the longest first: the HDF5 file, all VTI files (one after the other), each CSV file.
  std::vector<std::function<void()>> tasks;
  tasks.emplace_back([&] { write_dic_hdf5(h5, result, info); });
  if (vtk)
    tasks.emplace_back([&] {
      for (std::size_t k = 0; k < result.frames.size(); ++k)
        write_dic_vti(frame_output_path(h5, k, ".vti"), result, k, info);
    });
  if (csv)
    for (std::size_t k = 0; k < result.frames.size(); ++k)
      tasks.emplace_back(
          [&, k] { write_dic_csv(frame_output_path(h5, k, ".csv"), result, k, info); });
  std::vector<std::exception_ptr> errors(tasks.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, threads))
  for (int t = 0; t < static_cast<int>(tasks.size()); ++t) {
    try {
      tasks[static_cast<std::size_t>(t)]();
    } catch (...) {
      errors[static_cast<std::size_t>(t)] = std::current_exception();
    }
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

void write_ground_truth_hdf5(const std::filesystem::path& path, const Camera& camera,
                             const std::string& view, const std::vector<GroundTruth>& frames) {
  H5FieldFile h(path, "granoscope-render-truth");
  h.attr("view", view);
  h.attr("px_per_m", camera.px_per_m);
  h.attr("a0_m", camera.a0);
  h.attr("b0_m", camera.b0);
  h.attr("reference", "frame 0 of the input; u, v in px, image axes (x right, y down)");
  const auto rows = static_cast<std::size_t>(camera.rows),
             cols = static_cast<std::size_t>(camera.cols);
  std::vector<std::int32_t> grain;
  if (!frames.empty()) {
    const cv::Mat& g = frames.front().grain;
    grain.assign(g.begin<int>(), g.end<int>());
  }
  h.write("/grain", grain, {rows, cols});
  std::vector<float> u, v;
  std::vector<std::uint8_t> vis;
  for (const auto& f : frames) {
    for (auto it = f.u.begin<double>(); it != f.u.end<double>(); ++it)
      u.push_back(static_cast<float>(*it));
    for (auto it = f.v.begin<double>(); it != f.v.end<double>(); ++it)
      v.push_back(static_cast<float>(*it));
    vis.insert(vis.end(), f.visible.begin<std::uint8_t>(), f.visible.end<std::uint8_t>());
  }
  const std::vector<std::size_t> dims{frames.size(), rows, cols};
  h.write("/u", u, dims);
  h.write("/v", v, dims);
  h.write("/visible", vis, dims);
  h.commit();
}

}  // namespace gs::dic
