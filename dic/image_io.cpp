#include "image_io.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "errors.hpp"

namespace gs::dic {

cv::Mat read_grey_image(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path.string(), "no such image file");
  cv::Mat raw = cv::imread(path.string(), cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
  if (raw.empty()) throw InputError(path.string(), "cannot decode image");
  if (raw.channels() == 3)
    cv::cvtColor(raw, raw, cv::COLOR_BGR2GRAY);
  else if (raw.channels() == 4)
    cv::cvtColor(raw, raw, cv::COLOR_BGRA2GRAY);
  else if (raw.channels() != 1)
    throw InputError(path.string(), "unsupported channel count", std::to_string(raw.channels()));
  cv::Mat out;
  raw.convertTo(out, CV_64F);
  return out;
}

}  // namespace gs::dic
