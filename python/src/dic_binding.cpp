// granoscope.dic: subset DIC of an image sequence given as numpy arrays or file names, through
// the CLI's own run (dic/dic_run.hpp): same options, same checks, same numbers.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "common.hpp"
#include "dic_io.hpp"
#include "dic_run.hpp"
#include "errors.hpp"
#include "image_io.hpp"
#include "render_run.hpp"
#include "snapshot.hpp"

namespace py = pybind11;

namespace gs::py_bind {
namespace {

// A grey image: a file name (read as the CLI reads it) or a 2-D numpy array of uint8, uint16,
// float32 or float64 (viewed in place when C-contiguous).
cv::Mat to_image(py::handle obj, const std::string& name, std::vector<py::object>& keep) {
  if (py::isinstance<py::str>(obj) || py::hasattr(obj, "__fspath__")) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(obj));
    return dic::read_grey_image(path);
  }
  const auto dtype_map = [](const py::dtype& d) {
    if (d.is(py::dtype::of<std::uint8_t>())) return CV_8U;
    if (d.is(py::dtype::of<std::uint16_t>())) return CV_16U;
    if (d.is(py::dtype::of<float>())) return CV_32F;
    if (d.is(py::dtype::of<double>())) return CV_64F;
    return -1;
  };
  py::array a = py::array::ensure(obj, py::array::c_style);
  if (!a) throw InputError(name, "not an image (a file name or a 2-D numpy array)");
  if (a.ndim() != 2)
    throw InputError(name, "image must be a 2-D array", std::to_string(a.ndim()) + " dimensions");
  const int type = dtype_map(a.dtype());
  if (type < 0)
    throw InputError(name, "image dtype must be uint8, uint16, float32 or float64",
                     std::string(py::str(a.dtype())));
  keep.push_back(a);
  return cv::Mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), type,
                 const_cast<void*>(a.data()));
}

// Matrices of one type and size as a (frames, rows, cols) array of T.
template <class T>
py::array_t<T> stack(const std::vector<cv::Mat>& m, int rows, int cols) {
  py::array_t<T> out({static_cast<py::ssize_t>(m.size()), static_cast<py::ssize_t>(rows),
                      static_cast<py::ssize_t>(cols)});
  T* p = out.mutable_data();
  for (const auto& a : m)
    for (int r = 0; r < rows; ++r) p = std::copy(a.ptr<T>(r), a.ptr<T>(r) + cols, p);
  return out;
}

// One per-POI field of every frame as a (frames, ny, nx) array.
py::array_t<double> field(const dic::SequenceResult& r, const dic::DicColumn& c) {
  const auto nf = static_cast<py::ssize_t>(r.frames.size());
  py::array_t<double> out(
      {nf, static_cast<py::ssize_t>(r.grid.ny), static_cast<py::ssize_t>(r.grid.nx)});
  double* p = out.mutable_data();
  for (const auto& f : r.frames) p = std::copy(c.get(f).begin(), c.get(f).end(), p);
  return out;
}

}  // namespace

void bind_dic(py::module_& m) {
  m.def(
      "dic",
      [](py::sequence images, int subset, int step, const std::string& shape, py::object roi,
         bool incremental, int strain_window, const std::string& strain, double zncc_min,
         int search, int threads) {
        dic::DicRequest req;
        req.subset = subset;
        req.step = step;
        req.shape = shape;
        req.incremental = incremental;
        req.strain_window = strain_window;
        req.strain = strain;
        req.zncc_min = zncc_min;
        req.search = search;
        req.threads = threads;
        // Ctrl-C: between propagation fronts, take the GIL and look for a pending signal; its
        // exception (KeyboardInterrupt) unwinds the correlation.
        req.poll = raise_pending_signal;
        dic::check_request(req);
        std::vector<py::object> keep;
        std::vector<cv::Mat> mats;
        std::vector<std::string> names;
        for (std::size_t k = 0; k < images.size(); ++k) {
          const py::object im = images[k];
          names.push_back(py::isinstance<py::str>(im) || py::hasattr(im, "__fspath__")
                              ? std::string(py::str(py::module_::import("os").attr("fspath")(im)))
                              : "<image " + std::to_string(k) + ">");
          mats.push_back(to_image(im, names.back(), keep));
        }
        cv::Mat roi_mat;
        std::string roi_name = "<roi>";
        if (!roi.is_none()) roi_mat = to_image(roi, roi_name, keep);
        dic::SequenceResult r;
        {
          py::gil_scoped_release release;
          r = dic::run_dic(mats, names, roi_mat, roi_name, req);
        }
        py::dict out;
        const std::vector<double> x = dic::grid_x(r.grid), y = dic::grid_y(r.grid);
        out["x"] = py::array_t<double>(x.size(), x.data());
        out["y"] = py::array_t<double>(y.size(), y.data());
        for (const auto& c : dic::dic_columns()) out[c.name] = field(r, c);
        const auto nf = static_cast<py::ssize_t>(r.frames.size());
        py::array_t<bool> valid(
            {nf, static_cast<py::ssize_t>(r.grid.ny), static_cast<py::ssize_t>(r.grid.nx)});
        bool* v = valid.mutable_data();
        for (const auto& f : r.frames)
          for (const auto b : f.valid) *v++ = b != 0;
        out["valid"] = valid;
        out["vsg_px"] = r.frames.front().strain.vsg_px;
        out["subset_px"] = subset;
        out["step_px"] = step;
        out["shape_function"] = shape;
        const double pois =
            static_cast<double>(r.grid.size()) * static_cast<double>(r.frames.size());
        out["icgn_iterations_per_poi"] = static_cast<double>(r.icgn_iterations) / pois;
        py::dict seconds;
        seconds["prefilter"] = r.seconds_prefilter;
        seconds["seeds"] = r.seconds_seeds;
        seconds["propagation"] = r.seconds_propagation;
        seconds["strain"] = r.seconds_strain;
        out["seconds"] = seconds;
        return out;
      },
      py::arg("images"), py::kw_only(), py::arg("subset") = 31, py::arg("step") = 2,
      py::arg("shape") = "affine", py::arg("roi") = py::none(), py::arg("incremental") = false,
      py::arg("strain_window") = 15, py::arg("strain") = "green", py::arg("zncc_min") = 0.9,
      py::arg("search") = 30, py::arg("threads") = 0,
      "Subset DIC of images[1:] against images[0] (file names or 2-D arrays: uint8, uint16, "
      "float32, float64), as `granoscope dic`: returns x (nx,), y (ny,) POI coordinates (px) and "
      "u, v (px, reference grid, NaN where invalid), zncc, valid, exx, eyy, exy (Green-Lagrange), "
      "exx_small, eyy_small, exy_small of shape (frames, ny, nx), and vsg_px.");

  m.def(
      "render",
      [](py::object frames, const std::string& view, double px_per_d50, double margin_d50,
         int supersample, double noise, int bits, std::uint64_t seed) {
        dic::RenderRequest req;
        req.view = view;
        req.px_per_d50 = px_per_d50;
        req.margin_d50 = margin_d50;
        req.supersample = supersample;
        req.noise = noise;
        req.bits = bits;
        req.seed = seed;
        dic::check_render_request(req);
        const auto n = static_cast<long>(py::len(frames));
        if (n == 0) throw InputError("<trajectory>", "trajectory has no frames");
        const Frame ref = frames[py::int_(0)].cast<Frame>();
        const dic::Camera cam = dic::render_camera(ref, req, "<trajectory>");
        std::vector<cv::Mat> images, u, v, visible, grain;
        for (long k = 0; k < n; ++k) {
          const Frame f = k == 0 ? ref : frames[py::int_(k)].cast<Frame>();
          dic::RenderedFrame r;
          {
            py::gil_scoped_release unlocked;
            r = dic::render_one(ref, f, cam, req);
          }
          raise_pending_signal();
          images.push_back(r.image);
          u.push_back(r.truth.u);
          v.push_back(r.truth.v);
          visible.push_back(r.truth.visible);
          grain.push_back(r.truth.grain);
        }
        py::dict out;
        out["images"] = bits == 8 ? py::object(stack<std::uint8_t>(images, cam.rows, cam.cols))
                                  : py::object(stack<std::uint16_t>(images, cam.rows, cam.cols));
        out["u"] = stack<double>(u, cam.rows, cam.cols);
        out["v"] = stack<double>(v, cam.rows, cam.cols);
        out["visible"] = stack<std::uint8_t>(visible, cam.rows, cam.cols);
        out["grain"] = stack<std::int32_t>(grain, cam.rows, cam.cols);
        py::dict c;
        c["right"] = std::vector<double>{cam.right.x(), cam.right.y(), cam.right.z()};
        c["up"] = std::vector<double>{cam.up.x(), cam.up.y(), cam.up.z()};
        c["dir"] = std::vector<double>{cam.dir.x(), cam.dir.y(), cam.dir.z()};
        c["px_per_m"] = cam.px_per_m;
        c["a0"] = cam.a0;
        c["b0"] = cam.b0;
        c["rows"] = cam.rows;
        c["cols"] = cam.cols;
        out["camera"] = c;
        return out;
      },
      py::arg("frames"), py::kw_only(), py::arg("view") = "front", py::arg("px_per_d50") = 25.0,
      py::arg("margin_d50") = 0.5, py::arg("supersample") = 3, py::arg("noise") = 0.0,
      py::arg("bits") = 8, py::arg("seed") = 1,
      "Speckle images of DEM frames as `granoscope render` (a Trajectory or a list of Frames; "
      "the first is the reference the camera frames): images (frames, rows, cols) uint8 or "
      "uint16, and the exact ground truth from the reference to each frame: u, v (px, NaN where "
      "no grain), visible, grain (reference particle index, -1 background); camera (right, up, "
      "dir, px_per_m, a0, b0 in m: pixel (col, row) shows right.x = a0 + col / px_per_m).");
}

}  // namespace gs::py_bind
