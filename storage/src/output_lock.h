#pragma once
// One writer per output name. A writer holds an exclusive lock on "<path>.lock" from before
// it touches "<path>.partial" or <path> until it is done, so a second writer on the same name
// (another process, or another writer object in this one) is refused before it changes
// anything. HDF5's own file lock is no substitute: HDF5 1.10 truncates a file it creates
// before it locks it, drops the lock once SWMR writing starts, and is switched off by
// HDF5_USE_FILE_LOCKING=FALSE.
//
// The lock is flock(2) on a small sidecar file holding the writer's pid. The kernel releases
// it when the holder dies, however it dies, so a crash never leaves a name locked; a sidecar
// left by a crash is taken over by the next writer and removed when that writer is done.
#include <filesystem>
#include <string_view>

namespace tomorig::storage {

class OutputLock {
 public:
  OutputLock() = default;  // holds nothing
  // Throws tomorig::Error (bad_input) if another writer holds the lock of `output`, naming its
  // pid, or if the lock file cannot be created. `kind` names the file in messages ("session").
  static OutputLock acquire(const std::filesystem::path& output, std::string_view kind);
  ~OutputLock();
  OutputLock(OutputLock&& other) noexcept;
  OutputLock& operator=(OutputLock&& other) noexcept;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  bool held() const { return fd_ >= 0; }
  static std::filesystem::path lock_path(const std::filesystem::path& output);

 private:
  void release() noexcept;
  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace tomorig::storage
