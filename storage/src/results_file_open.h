#pragma once
// A version-2 results file open for appending under HDF5 SWMR: its /sets rows and /statistics
// datasets. Used by results_file_writer.cpp.
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "h5_error.h"
#include "h5_handle.h"
#include "results_file_rows.h"
#include "results_xdmf.h"

namespace tomorig::storage::results_detail {

// The open datasets of a file being appended to.
struct OpenFile {
  h5::File file;
  h5::RowDataset complete, set_index, dt, seconds, completed, report_span, report_text;
  h5::RowDataset displacement, velocity, status, peak;
  h5::Dataset stats_sets, valid_count, mean_displacement, mean_velocity, rms_velocity, reynolds;
  hsize_t next_row = 0;
  std::vector<XdmfSetRow> committed;  // finished sets and their rows, for the sidecar

  void commit(std::uint64_t set_index, hsize_t row) {
    std::erase_if(committed, [&](const XdmfSetRow& r) { return r.set_index == set_index; });
    committed.push_back({set_index, row});
  }
  std::vector<h5::RowDataset*> rows() {
    return {&complete, &set_index, &dt, &seconds, &completed, &report_span, &displacement, &velocity, &status, &peak};
  }
  // Opens `path` for appending under SWMR; nullopt if HDF5 refuses (e.g. the superblock of a
  // file whose writer died still says "open for writing"). Throws h5::Failure for a file that
  // opens but lacks the layout.
  static std::optional<OpenFile> open(const std::filesystem::path& path);
  void flush(const std::string& where) {
    h5::check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "cannot flush", where);
  }
  // Closes every object, then the file (which clears the "open for writing" mark).
  herr_t close() {
    for (h5::RowDataset* r : rows()) r->close();
    report_text.close();
    for (h5::Dataset* d : {&stats_sets, &valid_count, &mean_displacement, &mean_velocity, &rms_velocity, &reynolds})
      d->close();
    return file.close();
  }
};


// Writes a whole fixed-size dataset. Throws h5::Failure.
void write_whole(hid_t dataset, hid_t mem_type, const void* data, const char* where);

}  // namespace tomorig::storage::results_detail
