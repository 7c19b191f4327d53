#pragma once
// A dataset whose first dimension counts rows (sets, or bytes of report text) and grows in
// place: created once, or opened again to append to an existing results file.
#include <hdf5.h>

#include <string>
#include <vector>

#include "h5_handle.h"

namespace tomorig::storage::h5 {

class RowDataset {
 public:
  RowDataset() = default;
  // A new dataset of `file_type`, rows of `record_shape`, `rows_per_chunk` rows per chunk.
  static RowDataset create(hid_t location, const char* name, hid_t file_type, const std::vector<hsize_t>& record_shape,
                           hsize_t rows_per_chunk, const std::string& where);
  static RowDataset open(hid_t location, const char* name, const std::string& where);

  hsize_t rows() const { return dims_.empty() ? 0 : dims_[0]; }
  std::size_t record_size() const;  // elements per row
  void grow_to(hsize_t rows);
  // Writes or reads rows [first, first + count), contiguous in memory as `mem_type`.
  void write_rows(hsize_t first, hsize_t count, hid_t mem_type, const void* data);
  void read_rows(hsize_t first, hsize_t count, hid_t mem_type, void* out) const;
  bool valid() const { return dataset_.valid(); }
  herr_t close() { return dataset_.close(); }
  // One more reference, so that close() leaves the dataset open (see the writer's failure path).
  void keep_open() {
    if (dataset_.valid()) H5Iinc_ref(dataset_.get());
  }

 private:
  Dataset dataset_;
  std::string where_;
  std::vector<hsize_t> dims_;
};

}  // namespace tomorig::storage::h5
