// Grey-level image input for DIC, with the checks every DIC path needs.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

namespace gs::dic {

/// Reads an 8- or 16-bit image as a single-channel CV_64F image (colour converted to grey).
/// Throws InputError naming the file for a missing/unreadable file or an empty image.
cv::Mat read_grey_image(const std::filesystem::path& path);

/// Writes `image` to `path` (format from the extension); the encoder's own stderr lines (libpng's
/// "Write Error") become part of one InputError naming `name`.
void write_image(const std::filesystem::path& path, const cv::Mat& image, const std::string& name);

}  // namespace gs::dic
