// One DIC run as `granoscope dic` makes it: the options checked, the images checked against
// each other, the POI grid and the correlation of the sequence. The CLI (apps/cmd_dic.cpp) and
// the Python package (granoscope.dic) both call this, so they take the same options, print the
// same one-line errors (naming the CLI's options) and give the same numbers.
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "dic_io.hpp"
#include "dic_sequence.hpp"

namespace gs::dic {

struct DicRequest {
  int subset = 31;               // px, odd >= 5
  int step = 2;                  // px
  std::string shape = "affine";  // or "quadratic"
  int strain_window = 15;        // POIs, odd >= 3
  std::string strain = "green";  // CSV/VTK strain: green or small
  double zncc_min = 0.9;         // in (-1, 1)
  int search = 30;               // px, >= 0
  int threads = 0;               // 0: OpenMP's default
  bool incremental = false;
  std::function<void()> poll;  // see DicOptions::poll
};

/// The thread count a request runs on (threads, or OpenMP's default for 0).
int resolved_threads(const DicRequest& request);

/// Throws InputError naming the option (e.g. "--subset: must be an odd number of px >= 5 (30)").
void check_request(const DicRequest& request);

/// Correlates images[1..] with images[0] (or each with the previous one, incremental).
/// `names` name the images in messages (same length); `roi` is empty or a mask of the images'
/// size named `roi_name`. Throws InputError: too few images, sizes differ, an image without
/// texture, ROI of another size or without POI, image smaller than a subset, strain window
/// wider than the POI grid, no seed found.
SequenceResult run_dic(const std::vector<cv::Mat>& images, const std::vector<std::string>& names,
                       const cv::Mat& roi, const std::string& roi_name, const DicRequest& request);

/// What the output files record of a run.
DicRunInfo run_info(const DicRequest& request, const std::vector<std::string>& names,
                    const SequenceResult& result, const cv::Mat& reference);

}  // namespace gs::dic
