#include "dic_run.hpp"

#include <omp.h>

#include <algorithm>
#include <stdexcept>

#include "errors.hpp"

namespace gs::dic {
namespace {

std::string size_str(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

}  // namespace

int resolved_threads(const DicRequest& request) {
  return request.threads > 0 ? request.threads : omp_get_max_threads();
}

void check_request(const DicRequest& a) {
  if (a.subset < 5 || a.subset % 2 == 0)
    throw InputError("--subset", "must be an odd number of px >= 5", std::to_string(a.subset));
  if (a.step < 1) throw InputError("--step", "must be >= 1 px", std::to_string(a.step));
  if (a.shape != "affine" && a.shape != "quadratic")
    throw InputError("--shape", "must be affine or quadratic", a.shape);
  if (a.strain_window < 3 || a.strain_window % 2 == 0)
    throw InputError("--strain-window", "must be an odd number of POIs >= 3",
                     std::to_string(a.strain_window));
  if (a.strain != "green" && a.strain != "small")
    throw InputError("--strain", "must be green or small", a.strain);
  if (!(a.zncc_min > -1.0 && a.zncc_min < 1.0))
    throw InputError("--zncc-min", "must be in (-1, 1)", value_str(a.zncc_min));
  if (a.search < 0) throw InputError("--search", "must be >= 0 px", std::to_string(a.search));
  if (a.threads < 0 || a.threads > 1024)
    throw InputError("--threads", "must be in 0..1024", std::to_string(a.threads));
}

SequenceResult run_dic(const std::vector<cv::Mat>& images, const std::vector<std::string>& names,
                       const cv::Mat& roi, const std::string& roi_name, const DicRequest& a) {
  check_request(a);
  if (images.size() < 2) throw InputError("IMAGES", "need a reference and at least one image");
  if (names.size() != images.size()) throw std::invalid_argument("run_dic: one name per image");
  for (std::size_t k = 0; k < images.size(); ++k)
    if (images[k].empty() || images[k].channels() != 1)
      throw InputError(names[k], "not a single-channel (grey) image");
  for (std::size_t k = 1; k < images.size(); ++k)
    if (images[k].size() != images[0].size())
      throw InputError(names[k], "image size differs from the reference",
                       size_str(images[k]) + " vs " + size_str(images[0]));
  for (std::size_t k = 0; k < images.size(); ++k)
    if (is_textureless(images[k]))
      throw InputError(names[k], "image has no texture (uniform grey level)");
  if (!roi.empty() && roi.size() != images[0].size())
    throw InputError(roi_name, "ROI mask size differs from the images",
                     size_str(roi) + " vs " + size_str(images[0]));
  const int radius = a.subset / 2;
  if (images[0].cols < a.subset || images[0].rows < a.subset)
    throw InputError(names[0], "image smaller than one subset", size_str(images[0]));

  SequenceOptions opt;
  opt.dic.radius = radius;
  opt.dic.search = a.search;
  opt.dic.icgn.order = a.shape == "quadratic" ? 2 : 1;
  opt.dic.zncc_min = a.zncc_min;
  opt.dic.threads = resolved_threads(a);
  opt.step = a.step;
  opt.strain_window_radius = a.strain_window / 2;
  opt.incremental = a.incremental;
  opt.dic.poll = a.poll;

  PoiGrid grid;
  try {
    grid = make_grid(images[0].rows, images[0].cols, radius, a.step, roi);
  } catch (const std::invalid_argument& e) {
    throw InputError(roi.empty() ? names[0] : roi_name, e.what());
  }
  // A plane-fit window wider than the grid fits nothing: every strain would be NaN.
  if (a.strain_window > std::min(grid.nx, grid.ny))
    throw InputError("--strain-window", "larger than the POI grid",
                     std::to_string(a.strain_window) + " POIs; grid " + std::to_string(grid.nx) +
                         " x " + std::to_string(grid.ny));
  try {
    return correlate_sequence(images, roi, opt);
  } catch (const std::runtime_error& e) {
    throw InputError(names[0], "correlation failed", e.what());
  }
}

DicRunInfo run_info(const DicRequest& a, const std::vector<std::string>& names,
                    const SequenceResult& result, const cv::Mat& reference) {
  DicRunInfo info;
  info.images = names;
  info.subset_px = a.subset;
  info.step_px = a.step;
  info.shape_function = a.shape;
  info.strain_window_points = a.strain_window;
  info.vsg_px = result.frames.front().strain.vsg_px;
  info.incremental = a.incremental;
  info.small_strain = a.strain == "small";
  info.image_rows = reference.rows;
  info.image_cols = reference.cols;
  return info;
}

}  // namespace gs::dic
