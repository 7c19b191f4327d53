#include "output_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace {

// The pid a holder wrote into the lock file, or "" if it cannot be read.
std::string holder_pid(int fd) {
  char text[32] = {};
  const ssize_t n = pread(fd, text, sizeof text - 1, 0);
  if (n <= 0) return "";
  std::string pid(text, static_cast<std::size_t>(n));
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return pid;
}

bool same_file(int fd, const fs::path& path) {
  struct stat opened {}, named {};
  if (fstat(fd, &opened) != 0 || stat(path.c_str(), &named) != 0) return false;
  return opened.st_dev == named.st_dev && opened.st_ino == named.st_ino;
}

}  // namespace

fs::path OutputLock::lock_path(const fs::path& output) { return fs::path(output).concat(".lock"); }

OutputLock OutputLock::acquire(const fs::path& output, std::string_view kind) {
  const fs::path path = lock_path(output);
  // A holder removes the lock file when it is done, so the file this process opened may be
  // unlinked between open() and flock(): then the lock is on a dead file and the loop takes
  // the new one. Two rounds are enough unless another writer keeps racing for the name.
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throw bad_input(fmt::format("cannot create the lock file '{}' of {} file '{}' (is folder '{}' writable?): {}",
                                  path.string(), kind, output.string(), path.parent_path().string(),
                                  std::strerror(errno)));
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      const std::string pid = error == EWOULDBLOCK ? holder_pid(fd) : "";
      close(fd);
      if (error == EWOULDBLOCK)
        throw bad_input(fmt::format("{} file '{}' is being written by another process{}; nothing was changed: wait "
                                    "for that writer to finish, or choose another output name",
                                    kind, output.string(), pid.empty() ? "" : fmt::format(" (pid {})", pid)));
      throw bad_input(fmt::format("cannot lock '{}' for writing {} file '{}' ({}); tomorig needs file locks "
                                  "(flock) to keep two writers off one file: write to a local disk",
                                  path.string(), kind, output.string(), std::strerror(error)));
    }
    if (!same_file(fd, path)) {
      close(fd);
      continue;
    }
    const std::string pid = fmt::format("{}\n", getpid());
    if (ftruncate(fd, 0) != 0 || pwrite(fd, pid.data(), pid.size(), 0) < 0) {
      // The pid only improves a competitor's message; the lock holds without it.
    }
    OutputLock lock;
    lock.path_ = path;
    lock.fd_ = fd;
    return lock;
  }
  throw bad_input(fmt::format("cannot lock '{}': other writers keep taking {} file '{}'", path.string(), kind,
                              output.string()));
}

OutputLock::~OutputLock() { release(); }

OutputLock::OutputLock(OutputLock&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)) {}

OutputLock& OutputLock::operator=(OutputLock&& other) noexcept {
  if (this != &other) {
    release();
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

void OutputLock::release() noexcept {
  if (fd_ < 0) return;
  // Removed while still locked, so no other writer can hold a lock on this file by then (see
  // acquire(): a writer that opened it before the unlink finds it is no longer the named file).
  unlink(path_.c_str());
  close(fd_);
  fd_ = -1;
}

}  // namespace tomorig::storage
