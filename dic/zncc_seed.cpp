#include "zncc_seed.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace gs::dic {

IntegerMatch zncc_match(const cv::Mat& reference32, const cv::Mat& deformed32, int x0, int y0,
                        int radius, int search) {
  IntegerMatch m;
  const int side = 2 * radius + 1;
  if (x0 - radius < 0 || y0 - radius < 0 || x0 + radius >= reference32.cols ||
      y0 + radius >= reference32.rows)
    return m;
  const int wx0 = std::max(0, x0 - radius - search);
  const int wy0 = std::max(0, y0 - radius - search);
  const int wx1 = std::min(deformed32.cols, x0 + radius + search + 1);
  const int wy1 = std::min(deformed32.rows, y0 + radius + search + 1);
  if (wx1 - wx0 < side || wy1 - wy0 < side) return m;
  const cv::Mat tmpl = reference32(cv::Rect(x0 - radius, y0 - radius, side, side));
  const cv::Mat window = deformed32(cv::Rect(wx0, wy0, wx1 - wx0, wy1 - wy0));
  cv::Mat score;
  cv::matchTemplate(window, tmpl, score, cv::TM_CCOEFF_NORMED);
  double best = 0.0;
  cv::Point at;
  cv::minMaxLoc(score, nullptr, &best, nullptr, &at);
  m.u = wx0 + at.x + radius - x0;
  m.v = wy0 + at.y + radius - y0;
  m.zncc = best;
  m.ok = std::isfinite(best);
  return m;
}

}  // namespace gs::dic
