#include "h5_open.h"

#include <algorithm>
#include <cctype>
#include <string>

#include <fmt/format.h>

#include "h5_error.h"
#include "tomorig/core/error.h"

namespace tomorig::storage::h5 {

File open_for_reading(const std::filesystem::path& path, std::string_view kind) {
  namespace fs = std::filesystem;
  silence_errors();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw bad_input(fmt::format("{} '{}' does not exist", kind, path.string()));
  if (fs::is_directory(path, ec)) throw bad_input(fmt::format("'{}' is a folder, not a {}", path.string(), kind));
  const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
  if (is_hdf5 <= 0)
    throw bad_input(fmt::format("'{}' is not an HDF5 file, so not a tomorig {}{}", path.string(), kind,
                                is_hdf5 < 0 ? fmt::format(" ({})", error_stack_text()) : ""));
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  // A live recording (SWMR) refuses plain readers while it is written, and after a crash its
  // superblock still says "open for writing"; a SWMR reader reads both.
  std::string plain_reason;
  if (id < 0) {
    plain_reason = error_stack_text();
    // A SWMR reader takes a metadata checksum failure for a block the writer is rewriting and
    // reads it again, sleeping 1 ns, 2 ns, 4 ns, ... in between: HDF5's 100 attempts would
    // sleep for centuries on a block that is damaged, not torn. 24 attempts re-read for about
    // 17 ms, far longer than a writer takes to write a block.
    PropertyList fapl(H5Pcreate(H5P_FILE_ACCESS));
    if (fapl.valid()) H5Pset_metadata_read_attempts(fapl.get(), kSwmrReadAttempts);
    id = H5Fopen(path.c_str(), H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, fapl.valid() ? fapl.get() : H5P_DEFAULT);
  }
  if (id < 0) {
    std::string reason = error_stack_text();
    if (reason == kNoReason) reason = plain_reason;
    std::string lower = reason;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    // HDF5 1.10 locks files; a writer that has the file open holds the lock.
    if (lower.find("unable to lock") != std::string::npos)
      throw bad_input(fmt::format("{} '{}' is locked by another program (is it still being written?): {}", kind,
                                  path.string(), reason));
    throw bad_input(fmt::format("{} '{}' is corrupt or truncated: HDF5 cannot open it: {}", kind, path.string(),
                                reason));
  }
  return File(id);
}

}  // namespace tomorig::storage::h5
