// Grey-level image input for DIC, with the checks every DIC path needs.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

namespace gs::dic {

/// Reads an 8- or 16-bit image as a single-channel CV_64F image (colour converted to grey).
/// Throws InputError naming the file for a missing/unreadable file or an empty image.
cv::Mat read_grey_image(const std::filesystem::path& path);

}  // namespace gs::dic
