#pragma once
// Reading untrusted HDF5 metadata where a library crash cannot take the caller down.
//
// libhdf5 1.10 trusts the metadata it reads: a damaged file can make it read out of bounds
// (variable-length strings through H5HG_read, names through H5MM_xstrdup) or loop forever in
// its metadata cache. tomorig validates what it can itself (sizes, counts, types), but only
// the library can walk its own structures, so before a reader touches a file in this process
// it runs the same reads in a forked child first: if the child dies of a signal, or spins
// past a CPU-time limit, the file is reported as damaged and this process never reads it.
// The reads are deterministic, so once the child got through them, the parent does too.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace tomorig::storage {

struct ProbeLimits {
  // CPU time the child may use. The metadata pass of a session takes milliseconds (a million
  // sets: about a second); a damaged file that makes HDF5 loop spins until this limit.
  int cpu_seconds = 8;
  // Wall-clock backstop: a child still blocked after this (an inherited lock another thread
  // held at fork(), a stalled network disk) proves nothing about the file and is not counted
  // as damage; the caller then reads in-process as it would without the probe.
  int wall_seconds = 60;
};

// Runs `reads` in a forked child (exceptions it throws are ignored: the caller's own pass
// reports them). Returns nothing if the child got through or the result is inconclusive,
// else why the reads are unsafe, e.g. "crashed the HDF5 library (signal 11, Segmentation
// fault)". Call only where no other thread of this process is inside HDF5.
std::optional<std::string> probe_in_child(const std::function<void()>& reads, const ProbeLimits& limits = {});

// probe_in_child(reads), then throws tomorig::Error (bad_input) naming `kind` ("session file")
// and `path` if the reads are unsafe. Readers call it before their own pass.
void require_safe_to_read(const std::function<void()>& reads, std::string_view kind,
                          const std::filesystem::path& path);

}  // namespace tomorig::storage
