// DIC over an image sequence: cumulative (every image against the first, as seed 004) or
// incremental (each image against the previous one, displacements accumulated in the reference
// configuration), with plane-fit strain per frame.
#pragma once

#include <string>
#include <vector>

#include "dic_strain.hpp"
#include "reliability_guided.hpp"

namespace gs::dic {

struct SequenceOptions {
  DicOptions dic;
  int step = 2;
  int strain_window_radius = 7;  // m: (2m+1)^2 POIs per plane fit
  bool incremental = false;
};

/// Fields of one deformed image on the reference POI grid (Lagrangian, px).
struct FrameResult {
  std::vector<double> u, v, zncc;
  std::vector<std::uint8_t> valid;
  StrainField strain;
};

struct SequenceResult {
  PoiGrid grid;
  std::vector<FrameResult> frames;  // one per image after the reference
  // Wall-clock seconds summed over the frames (DicField's stages, then the plane-fit strain).
  double seconds_prefilter = 0.0, seconds_seeds = 0.0, seconds_propagation = 0.0;
  double seconds_strain = 0.0;
  long long icgn_iterations = 0;  // summed over the frames' solved POIs
};

/// images[0] is the reference. All images must have the same size. `roi` optional (CV_8U).
/// Throws std::invalid_argument / std::runtime_error with the 1-based image index on failure.
SequenceResult correlate_sequence(const std::vector<cv::Mat>& images, const cv::Mat& roi,
                                  const SequenceOptions& options);

/// Grey-level standard deviation below which an image has no usable texture.
bool is_textureless(const cv::Mat& image);

}  // namespace gs::dic
