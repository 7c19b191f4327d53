#pragma once
// The "<path>.partial" file a session is written to. Until released, destroying the guard
// deletes the file, so a writer that is abandoned, or whose constructor fails half-way,
// leaves nothing behind.
#include <filesystem>
#include <system_error>
#include <utility>

namespace tomorig::storage {

class PartialFile {
 public:
  explicit PartialFile(std::filesystem::path path) : path_(std::move(path)) {}
  ~PartialFile() {
    std::error_code ignored;  // a destructor cannot report; the file is in a temp-like state anyway
    if (armed_) std::filesystem::remove(path_, ignored);
  }
  PartialFile(const PartialFile&) = delete;
  PartialFile& operator=(const PartialFile&) = delete;

  const std::filesystem::path& path() const { return path_; }
  void arm() { armed_ = true; }       // the file now exists and is ours
  void release() { armed_ = false; }  // renamed to its final name: keep it

 private:
  std::filesystem::path path_;
  bool armed_ = false;
};

}  // namespace tomorig::storage
