#include "image_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "atomic_file.hpp"
#include "errors.hpp"

namespace gs::dic {

namespace {

// DIC holds each image as doubles (8 bytes a pixel) and several derived images of the same size:
// 10^8 pixels (10 000 x 10 000) is already 800 MB an image.
constexpr std::uint64_t kMaxPixels = 100'000'000;

std::uint32_t be32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

// A PNG's size from its IHDR chunk, before anything is decoded (a 250 kB PNG can claim
// 16 000 x 16 000 pixels).
void check_png_size(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[24] = {};
  in.read(reinterpret_cast<char*>(h), sizeof h);
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (in.gcount() != sizeof h || !std::equal(sig, sig + 8, h)) return;          // not a PNG
  if (std::string(reinterpret_cast<const char*>(h + 12), 4) != "IHDR") return;  // (decoder says)
  const std::uint64_t w = be32(h + 16), ht = be32(h + 20);
  if (w * ht > kMaxPixels)
    throw InputError(path.string(), "image too large",
                     std::to_string(w) + " x " + std::to_string(ht) + " pixels, at most " +
                         std::to_string(kMaxPixels));
}

// The decoders (libpng, libtiff, libjpeg) print their own diagnostics on stderr: while one runs,
// stderr goes to a temporary file, whose first line becomes part of our one error line.
class CapturedStderr {
 public:
  CapturedStderr() {
    std::fflush(stderr);
    file_ = std::tmpfile();
    saved_ = ::dup(STDERR_FILENO);
    if (file_ && saved_ >= 0) ::dup2(::fileno(file_), STDERR_FILENO);
  }
  CapturedStderr(const CapturedStderr&) = delete;
  CapturedStderr& operator=(const CapturedStderr&) = delete;
  ~CapturedStderr() {
    restore();
    if (file_) std::fclose(file_);
  }
  /// Restores stderr and returns the first line the decoder printed (empty if none).
  std::string first_line() {
    restore();
    if (!file_) return {};
    std::rewind(file_);
    char buf[200] = {};
    if (!std::fgets(buf, sizeof buf, file_)) return {};
    std::string s = buf;
    if (!s.empty() && s.back() == '\n') s.pop_back();
    return s;
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
    saved_ = -1;
  }
  std::FILE* file_ = nullptr;
  int saved_ = -1;
};

}  // namespace

cv::Mat read_grey_image(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path.string(), "no such image file");
  check_png_size(path);
  note_input(path);
  cv::Mat raw;
  std::string said;
  {
    CapturedStderr capture;
    try {
      raw = cv::imread(path.string(), cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
    } catch (const cv::Exception& e) {
      said = capture.first_line();
      throw InputError(path.string(), "cannot decode image",
                       said.empty() ? std::string(e.err.substr(0, 120)) : said);
    }
    said = capture.first_line();
  }
  if (raw.empty()) throw InputError(path.string(), "cannot decode image", said);
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

void write_image(const std::filesystem::path& path, const cv::Mat& image, const std::string& name) {
  std::string said;
  bool written = false;
  {
    CapturedStderr capture;
    try {
      written = cv::imwrite(path.string(), image);
    } catch (const cv::Exception& e) {
      said = capture.first_line();
      throw InputError(name, "cannot write image",
                       said.empty() ? std::string(e.err.substr(0, 120)) : said);
    }
    said = capture.first_line();
  }
  if (!written) throw InputError(name, "cannot write image", said);
}

}  // namespace gs::dic
