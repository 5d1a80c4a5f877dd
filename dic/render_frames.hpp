// Speckle rendering of DEM snapshots for DIC, with exact ground truth. Orthographic camera
// looking at one face of the specimen (e.g. through a transparent front wall): each pixel shows
// the first sphere its ray hits. Every grain carries a natural-looking texture fixed to its body
// (a random grey level plus random spots on its surface), so translation and rotation of the
// grains move the texture exactly. The ground truth of a reference pixel is the image motion of
// the surface material point it shows.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "snapshot.hpp"

namespace gs::dic {

enum class View { Front, Back, Left, Right, Top, Bottom };

/// "front" (looking along +y, image x = +x, up = +z), "back", "left", "right", "top", "bottom".
View parse_view(const std::string& name);

struct Camera {
  Eigen::Vector3d right;  // image +x
  Eigen::Vector3d up;     // image -row
  Eigen::Vector3d dir;    // into the specimen
  double px_per_m = 0.0;
  double a0 = 0.0;  // right-coordinate of pixel column 0 centre (m)
  double b0 = 0.0;  // up-coordinate of pixel row 0 centre (m)
  int rows = 0;
  int cols = 0;
  Eigen::Vector2d to_pixel(const Eigen::Vector3d& p) const {
    return {(p.dot(right) - a0) * px_per_m, (b0 - p.dot(up)) * px_per_m};
  }
};

/// Camera framing the particles of `frame` plus `margin_d50` on each side, at `px_per_d50`
/// (d50 = median particle diameter by count). Throws InputError for an empty frame.
Camera make_camera(const Frame& frame, View view, double px_per_d50, double margin_d50,
                   const std::string& source);

struct RenderOptions {
  int supersample = 3;       // s x s rays per pixel
  double noise_sigma = 0.0;  // additive Gaussian noise, grey levels (0..255)
  std::uint64_t seed = 1;    // grain textures and noise
  double background = 15.0;  // grey level where no grain is hit
};

/// Grey image (CV_64F, 0..255, not quantised) of `frame`. Grains are matched across frames by
/// particle id.
cv::Mat render_frame(const Frame& frame, const Camera& camera, const RenderOptions& options);

/// Exact image displacement (px) from `reference` to `current` of the material point shown at
/// each reference pixel centre. u, v: CV_64F, NaN where the reference pixel shows no grain or
/// the grain is missing in `current`; visible: CV_8U, 1 where the point is still the first hit.
struct GroundTruth {
  cv::Mat u, v;
  cv::Mat visible;
  cv::Mat grain;  // CV_32S index into reference.particles, -1 for background
};
GroundTruth ground_truth(const Frame& reference, const Frame& current, const Camera& camera);

}  // namespace gs::dic
