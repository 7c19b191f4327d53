#pragma once
// A small, really full-able disk for disk-full tests: a tmpfs of a few MB mounted on a fresh
// temporary folder (needs root; otherwise available() is false and why() says so, for a
// GTEST_SKIP). Unmounted and removed when the test ends.
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include "temp_dir.h"

namespace tomorig::testing {

class SmallTmpfs {
 public:
  explicit SmallTmpfs(std::size_t megabytes) {
    if (geteuid() != 0) {
      why_ = "mounting a small tmpfs to fill needs root; run the test as root to exercise a full disk";
      return;
    }
    const std::string options = "size=" + std::to_string(megabytes) + "m";
    if (mount("tomorig-disk-full-test", dir_.path().c_str(), "tmpfs", MS_NOSUID | MS_NODEV, options.c_str()) != 0) {
      why_ = std::string("cannot mount a tmpfs (") + std::strerror(errno) + "), so a full disk cannot be made here";
      return;
    }
    mounted_ = true;
  }
  ~SmallTmpfs() {
    if (mounted_) umount2(dir_.path().c_str(), MNT_DETACH);
  }
  SmallTmpfs(const SmallTmpfs&) = delete;
  SmallTmpfs& operator=(const SmallTmpfs&) = delete;

  bool available() const { return mounted_; }
  const std::string& why() const { return why_; }
  std::filesystem::path operator/(const std::string& name) const { return dir_ / name; }

 private:
  TempDir dir_;
  bool mounted_ = false;
  std::string why_;
};

}  // namespace tomorig::testing
