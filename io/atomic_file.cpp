#include "atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <set>
#include <system_error>
#include <vector>

#include "errors.hpp"

namespace gs {

namespace {
std::atomic<unsigned> g_counter{0};

std::mutex g_inputs_mutex;
std::set<std::pair<dev_t, ino_t>> g_inputs;  // (device, inode) of every input read

int g_scopes = 0;

}  // namespace

InputScope::InputScope() {
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  ++g_scopes;
}

InputScope::~InputScope() {
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  if (--g_scopes == 0) g_inputs.clear();
}

void note_input(const std::filesystem::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  if (g_scopes > 0) g_inputs.emplace(st.st_dev, st.st_ino);
}

void forget_input(const std::filesystem::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  g_inputs.erase({st.st_dev, st.st_ino});
}

void check_not_an_input(const std::filesystem::path& target) {
  struct stat st {};
  if (::stat(target.c_str(), &st) != 0) return;
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  if (g_inputs.count({st.st_dev, st.st_ino}))
    throw InputError(target.string(), "output would replace an input");
}

void sync_to_disk(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path.string(), "cannot open to sync to disk", std::strerror(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  // A directory on a filesystem that cannot sync directories (EINVAL) is not an error.
  if (rc != 0 && !(err == EINVAL && std::filesystem::is_directory(path)))
    throw InputError(path.string(), "cannot write output to disk", std::strerror(err));
}

void rename_durably(const std::filesystem::path& from, const std::filesystem::path& to) {
  check_not_an_input(to);
  sync_to_disk(from);
  std::error_code ec;
  std::filesystem::rename(from, to, ec);
  if (ec) throw InputError(to.string(), "cannot rename output into place", ec.message());
  const auto parent = to.has_parent_path() ? to.parent_path() : std::filesystem::path(".");
  sync_to_disk(parent);
}

AtomicOutput::AtomicOutput(std::filesystem::path target) : target_(std::move(target)) {
  const auto parent =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(parent, ec))
    throw InputError(target_.string(), "output directory does not exist", parent.string());
  check_not_an_input(target_);
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
  rename_durably(temp_, target_);
  committed_ = true;
}

StagingDir::StagingDir(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir_, ec))
    throw InputError(dir_.string(), "output directory does not exist");
  staging_ = dir_ / (".staging-" + std::to_string(::getpid()) + "-" + std::to_string(g_counter++));
  std::filesystem::create_directory(staging_, ec);
  if (ec) throw InputError(staging_.string(), "cannot create directory", ec.message());
}

StagingDir::~StagingDir() {
  std::error_code ec;
  std::filesystem::remove_all(staging_, ec);
}

InputError with_dir_renamed(const InputError& e, const std::filesystem::path& from_dir,
                            const std::filesystem::path& to_dir) {
  std::string m = e.what();
  const std::string from = from_dir.string() + "/", to = to_dir.string() + "/";
  for (auto k = m.find(from); k != std::string::npos; k = m.find(from, k + to.size()))
    m.replace(k, from.size(), to);
  const auto colon = m.find(": ");
  if (colon == std::string::npos) return InputError(to_dir.string(), m);
  return InputError(m.substr(0, colon), m.substr(colon + 2));
}

InputError StagingDir::renamed(const InputError& e) const {
  return with_dir_renamed(e, staging_, dir_);
}

void StagingDir::commit() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(staging_)) files.push_back(e.path());
  for (const auto& f : files) {
    sync_to_disk(f);
    std::error_code ec;
    std::filesystem::rename(f, dir_ / f.filename(), ec);
    if (ec)
      throw InputError((dir_ / f.filename()).string(), "cannot rename output into place",
                       ec.message());
  }
  sync_to_disk(dir_);
  committed_ = true;
}

}  // namespace gs
