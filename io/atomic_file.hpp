// Outputs are written under a temporary name beside the target and renamed into place only when
// complete, so a failed or killed run never leaves a partial file under the final name.
#pragma once

#include <filesystem>
#include <string>

namespace gs {

class AtomicOutput {
 public:
  /// Reserves `<target>.tmp-<pid>-<n>`; the parent directory must exist.
  explicit AtomicOutput(std::filesystem::path target);
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicOutput();

  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  /// Renames the temporary file onto the target (atomic on one filesystem).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

}  // namespace gs
