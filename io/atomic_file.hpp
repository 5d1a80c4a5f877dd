// Outputs are written under a temporary name beside the target and renamed into place only when
// complete, so a failed or killed run never leaves a partial file under the final name.
#pragma once

#include <filesystem>
#include <string>

#include "errors.hpp"

namespace gs {

/// While one is alive (the CLI holds one for the whole command), every input the readers open is
/// recorded, and no output may replace one, through any name (symbolic or hard links included).
class InputScope {
 public:
  InputScope();
  InputScope(const InputScope&) = delete;
  InputScope& operator=(const InputScope&) = delete;
  ~InputScope();
};
/// Records `path` as an input when an InputScope is alive (readers call it).
void note_input(const std::filesystem::path& path);
/// Forgets `path` as an input: a command's own state that it reads and then replaces (the
/// checkpoint index of `simulate --resume`).
void forget_input(const std::filesystem::path& path);
/// Throws InputError "TARGET: output would replace an input" when `target` is a noted input.
void check_not_an_input(const std::filesystem::path& target);

/// The error `e` with every `from/` in its message read as `to/` (a temporary directory named as
/// the final one it stands for).
InputError with_dir_renamed(const InputError& e, const std::filesystem::path& from,
                            const std::filesystem::path& to);

/// fsync of a file or directory; throws InputError naming it (a full disk shows here).
void sync_to_disk(const std::filesystem::path& path);
/// sync_to_disk(from), rename onto `to`, sync the directory of `to`.
void rename_durably(const std::filesystem::path& from, const std::filesystem::path& to);

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
  /// Syncs the temporary file to disk, renames it onto the target (atomic on one filesystem) and
  /// syncs the directory: after a power loss the target is the old file or the complete new one.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

/// Several outputs that appear together or not at all: each is written into a hidden staging
/// directory `<dir>/.staging-<pid>-<n>` and commit() moves them into `dir` (durably). Without
/// commit() the staging directory is removed with what it holds: a failed run (a full disk) leaves
/// no file under a final name.
class StagingDir {
 public:
  /// Creates the staging directory; `dir` must exist.
  explicit StagingDir(std::filesystem::path dir);
  StagingDir(const StagingDir&) = delete;
  StagingDir& operator=(const StagingDir&) = delete;
  ~StagingDir();

  /// Where an output of the final directory named `name` is written until commit().
  std::filesystem::path operator/(const std::filesystem::path& name) const {
    return staging_ / name;
  }
  const std::filesystem::path& final_dir() const { return dir_; }
  /// Moves every file of the staging directory into the final directory.
  void commit();
  /// Runs `write` (which writes into the staging directory); an InputError it throws is rethrown
  /// naming the final directory instead of the staging one.
  template <class F>
  void write(F&& write) const {
    try {
      write();
    } catch (const InputError& e) {
      throw renamed(e);
    }
  }

 private:
  InputError renamed(const InputError& e) const;

 public:
 private:
  std::filesystem::path dir_, staging_;
  bool committed_ = false;
};

}  // namespace gs
