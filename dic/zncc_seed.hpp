// Integer-pixel initial guess by zero-normalised cross-correlation (OpenCV matchTemplate,
// TM_CCOEFF_NORMED) of one reference subset over a search window of the deformed image.
#pragma once

#include <opencv2/core.hpp>

namespace gs::dic {

struct IntegerMatch {
  int u = 0;
  int v = 0;
  double zncc = -1.0;
  bool ok = false;  // false: subset or search window outside the images
};

/// Best integer displacement of the (2*radius+1)^2 subset centred at (x0, y0) of `reference`
/// within +-search px in `deformed` (window clipped to the image). Images CV_32F.
IntegerMatch zncc_match(const cv::Mat& reference32, const cv::Mat& deformed32, int x0, int y0,
                        int radius, int search);

}  // namespace gs::dic
