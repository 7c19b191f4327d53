#pragma once
// How HDF5 failures surface. HDF5's own error printing is switched off: users see one
// tomorig::Error that names the file and object, with HDF5's reason appended. The storage
// code throws h5::Failure from the low-level helpers, and the session reader and writer turn
// it into tomorig::Error, because only they know whether a failure means bad input (a
// corrupt file being read) or a runtime failure (a disk filling up while writing).
#include <hdf5.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace tomorig::storage::h5 {

class Failure : public std::runtime_error {
 public:
  explicit Failure(const std::string& what) : std::runtime_error(what) {}
};

// Switches off HDF5's automatic error printing for the calling thread (the library on Debian
// is thread-safe, and thread-safe builds keep error settings per thread). Cheap after the
// first call on a thread, so every public entry point calls it.
void silence_errors();

// HDF5's reason for the failure that just happened: the outermost and innermost messages of
// the calling thread's error stack, e.g. "unable to open file (truncated file: eof = 800, ...)".
std::string error_stack_text();
inline constexpr std::string_view kNoReason = "no reason given by HDF5";  // what it returns for an empty stack

// Throws Failure("<action> <object>: <reason>") when an HDF5 call returned a negative value.
// The message is built only on failure, so this is free on the hot path.
[[noreturn]] void fail(std::string_view action, std::string_view object);

template <typename Status>
Status check(Status status, std::string_view action, std::string_view object) {
  if (status < 0) fail(action, object);
  return status;
}

}  // namespace tomorig::storage::h5
