#include "atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <system_error>

#include "errors.hpp"

namespace gs {

namespace {
std::atomic<unsigned> g_counter{0};
}

AtomicOutput::AtomicOutput(std::filesystem::path target) : target_(std::move(target)) {
  const auto parent =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(parent, ec))
    throw InputError(target_.string(), "output directory does not exist", parent.string());
  temp_ = target_;
  temp_ += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(g_counter++);
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicOutput::commit() {
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) throw InputError(target_.string(), "cannot rename output into place", ec.message());
  committed_ = true;
}

}  // namespace gs
