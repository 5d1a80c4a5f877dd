// `granoscope dic REF IMG... -o dic.h5`: subset DIC of an image sequence (dic/).

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "dic_io.hpp"
#include "dic_run.hpp"
#include "dic_sequence.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "image_io.hpp"
#include "render_frames.hpp"
#include "render_run.hpp"

namespace gs::cli {
namespace {

struct DicArgs {
  std::vector<std::string> images;
  std::string output;
  std::string roi;
  dic::DicRequest req;
  bool no_csv = false;
  bool no_vtk = false;
};

void run_dic(const DicArgs& a) {
  if (a.images.size() < 2) throw InputError("IMAGES", "need a reference and at least one image");
  dic::check_request(a.req);  // before reading any image
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  const auto t_start = Clock::now();
  std::vector<cv::Mat> images;
  for (const auto& p : a.images) images.push_back(dic::read_grey_image(p));
  cv::Mat roi;
  if (!a.roi.empty()) roi = dic::read_grey_image(a.roi);
  const double seconds_read = since(t_start);
  const dic::SequenceResult result = dic::run_dic(images, a.images, roi, a.roi, a.req);
  const dic::DicRunInfo info = dic::run_info(a.req, a.images, result, images[0]);
  const int threads = dic::resolved_threads(a.req);
  const auto t_write = Clock::now();
  const std::filesystem::path out(a.output);
  // The HDF5, CSV and VTI files appear together or not at all.
  StagingDir staging(out.has_parent_path() ? out.parent_path() : std::filesystem::path("."));
  std::ostringstream report;  // printed once everything is in place
  staging.write([&] {
    dic::write_dic_outputs(staging / out.filename(), result, info, !a.no_csv, !a.no_vtk, threads);
  });
  for (std::size_t k = 0; k < result.frames.size(); ++k) {
    std::size_t nvalid = 0;
    for (const auto v : result.frames[k].valid) nvalid += v;
    report << a.images[k + 1] << ": " << nvalid << "/" << result.frames[k].valid.size()
           << " valid POIs\n";
  }
  staging.commit();
  const double seconds_write = since(t_write);
  const double seconds_total = since(t_start);
  std::cout << report.str();
  const double pois =
      static_cast<double>(result.grid.size()) * static_cast<double>(result.frames.size());
  char timing[512];
  std::snprintf(timing, sizeof timing,
                "time: read %.2f s, prefilter %.2f s, seeds %.2f s, propagation %.2f s (%.2f "
                "IC-GN iterations per POI), strain %.2f s, write %.2f s; %.0f POIs in %.2f s = "
                "%.3g POI/s end to end (%d threads)\n",
                seconds_read, result.seconds_prefilter, result.seconds_seeds,
                result.seconds_propagation, static_cast<double>(result.icgn_iterations) / pois,
                result.seconds_strain, seconds_write, pois, seconds_total, pois / seconds_total,
                threads);
  std::cout << timing;
  std::cout << "wrote " << out.string() << " (subset " << a.req.subset << " px, step " << a.req.step
            << " px, VSG " << info.vsg_px << " px)\n";
}

struct RenderArgs {
  std::string input;
  std::string out_dir;
  std::string format = "png";
  dic::RenderRequest req;
};

void run_render(const RenderArgs& a) {
  dic::check_render_request(a.req);
  if (a.format != "png" && a.format != "tif")
    throw InputError("--format", "must be png or tif", a.format);
  if (!std::filesystem::is_regular_file(a.input)) throw InputError(a.input, "no such file");
  const TrajectoryReader reader(a.input);
  if (reader.frame_count() == 0) throw InputError(a.input, "trajectory has no frames");
  const Frame ref = reader.frame(0);
  const dic::Camera cam = dic::render_camera(ref, a.req, a.input);
  std::error_code ec;
  std::filesystem::create_directories(a.out_dir, ec);
  if (!std::filesystem::is_directory(a.out_dir))
    throw InputError(a.out_dir, "cannot create output directory");
  std::vector<dic::GroundTruth> truth;
  StagingDir staging(a.out_dir);
  staging.write([&] {
    for (std::size_t k = 0; k < reader.frame_count(); ++k) {
      dic::RenderedFrame r = dic::render_one(ref, k == 0 ? ref : reader.frame(k), cam, a.req);
      char name[64];
      std::snprintf(name, sizeof name, "frame_%04zu.%s", k, a.format.c_str());
      const std::filesystem::path target = std::filesystem::path(a.out_dir) / name;
      const std::filesystem::path staged = staging / name;  // imwrite needs the extension
      dic::write_image(staged, r.image, target.string());
      truth.push_back(std::move(r.truth));
    }
    dic::write_ground_truth_hdf5(staging / "ground_truth.h5", cam, a.req.view, truth);
  });
  staging.commit();  // the frames and their ground truth appear together or not at all
  std::cout << "rendered " << reader.frame_count() << " frames " << cam.cols << "x" << cam.rows
            << " px (" << a.req.px_per_d50 << " px per d50) to " << a.out_dir << "\n";
}

}  // namespace

void register_dic(CLI::App& app) {
  auto rargs = std::make_shared<RenderArgs>();
  auto* r =
      app.add_subcommand("render", "Speckle images of DEM frames for DIC, with exact ground truth");
  r->add_option("input", rargs->input, "trajectory RUN.h5")->required();
  r->add_option("-o,--output", rargs->out_dir, "output directory (frame_NNNN.png, ground_truth.h5)")
      ->required();
  r->add_option("--view", rargs->req.view, "front, back, left, right, top or bottom")
      ->capture_default_str();
  r->add_option("--px-per-d50", rargs->req.px_per_d50, "pixels per median grain diameter")
      ->capture_default_str();
  r->add_option("--margin", rargs->req.margin_d50, "margin around the grains, in d50")
      ->capture_default_str();
  r->add_option("--supersample", rargs->req.supersample, "s x s rays per pixel")
      ->capture_default_str();
  r->add_option("--noise", rargs->req.noise, "Gaussian noise sigma, fraction of full scale")
      ->capture_default_str();
  r->add_option("--bits", rargs->req.bits, "8 or 16")->capture_default_str();
  r->add_option("--format", rargs->format, "png or tif")->capture_default_str();
  r->add_option("--seed", rargs->req.seed, "grain textures and noise")->capture_default_str();
  r->callback([rargs] { run_render(*rargs); });

  auto args = std::make_shared<DicArgs>();
  auto* c = app.add_subcommand("dic", "Subset digital image correlation of an image sequence");
  c->add_option("images", args->images, "reference image, then the deformed images")
      ->required()
      ->expected(2, -1);
  c->add_option("-o,--output", args->output, "output HDF5 file (CSV and .vti written beside)")
      ->required();
  c->add_option("--subset", args->req.subset, "subset size, px (odd)")->capture_default_str();
  c->add_option("--step", args->req.step, "POI spacing, px")->capture_default_str();
  c->add_option("--shape", args->req.shape,
                "subset shape function: affine (first order) or quadratic (second order)")
      ->capture_default_str();
  c->add_option("--roi", args->roi, "region-of-interest mask image (non-zero = inside)");
  c->add_flag("--incremental", args->req.incremental,
              "correlate each image with the previous one and accumulate (default: cumulative)");
  c->add_option("--strain-window", args->req.strain_window, "strain plane-fit window, POIs (odd)")
      ->capture_default_str();
  c->add_option("--strain", args->req.strain, "strain in CSV/VTK: green or small")
      ->capture_default_str();
  c->add_option("--zncc-min", args->req.zncc_min, "POIs below this ZNCC are invalid")
      ->capture_default_str();
  c->add_option("--search", args->req.search, "seed search half-width, px")->capture_default_str();
  c->add_option("--threads", args->req.threads, "threads (0 = OpenMP default, at most 1024)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->add_flag("--no-csv", args->no_csv, "do not write CSV tables");
  c->add_flag("--no-vtk", args->no_vtk, "do not write VTK images");
  c->callback([args] { run_dic(*args); });
}

}  // namespace gs::cli
