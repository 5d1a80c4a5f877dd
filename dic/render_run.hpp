// Rendering DEM frames as speckle images, as `granoscope render` does it and Python's
// granoscope.render: the options and their checks, the camera of the reference frame, and each
// frame's image quantised to 8 or 16 bits with its exact ground-truth displacement. One
// implementation for both faces (the CLI adds the files).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "render_frames.hpp"
#include "snapshot.hpp"

namespace gs::dic {

struct RenderRequest {
  std::string view = "front";  // front, back, left, right, top, bottom
  double px_per_d50 = 25.0;
  double margin_d50 = 0.5;
  int supersample = 3;  // s x s rays per pixel, 1..16
  double noise = 0.0;   // Gaussian noise sigma, fraction of full scale, [0, 1)
  int bits = 8;         // 8 or 16
  std::uint64_t seed = 1;
};

/// Throws InputError (naming the option) for a bad request; before any frame is read.
void check_render_request(const RenderRequest& r);

/// The camera looking at the reference frame (all frames are seen through it).
Camera render_camera(const Frame& reference, const RenderRequest& r, const std::string& source);

struct RenderedFrame {
  cv::Mat image;  // CV_8U or CV_16U (bits), rounded and saturated
  GroundTruth truth;
};

/// Frame `f` through `camera`, and the displacement from `reference` to it.
RenderedFrame render_one(const Frame& reference, const Frame& f, const Camera& camera,
                         const RenderRequest& r);

}  // namespace gs::dic
