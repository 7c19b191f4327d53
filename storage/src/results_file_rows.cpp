#include "results_file_rows.h"

#include "h5_datasets.h"
#include "h5_error.h"

namespace tomorig::storage::h5 {

RowDataset RowDataset::create(hid_t location, const char* name, hid_t file_type,
                              const std::vector<hsize_t>& record_shape, hsize_t rows_per_chunk,
                              const std::string& where) {
  RowDataset d;
  d.where_ = where;
  d.dims_.assign(1, 0);
  d.dims_.insert(d.dims_.end(), record_shape.begin(), record_shape.end());
  std::vector<hsize_t> max_dims = d.dims_;
  max_dims[0] = H5S_UNLIMITED;
  std::vector<hsize_t> chunk = d.dims_;
  chunk[0] = rows_per_chunk;
  const int rank = static_cast<int>(d.dims_.size());
  Dataspace space(check(H5Screate_simple(rank, d.dims_.data(), max_dims.data()), "cannot create", where));
  PropertyList dcpl(check(H5Pcreate(H5P_DATASET_CREATE), "cannot create", where));
  check(H5Pset_chunk(dcpl.get(), rank, chunk.data()), "cannot set the chunk shape of", where);
  d.dataset_ = Dataset(check(H5Dcreate2(location, name, file_type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                             "cannot create", where));
  return d;
}

RowDataset RowDataset::open(hid_t location, const char* name, const std::string& where) {
  RowDataset d;
  d.where_ = where;
  d.dataset_ = open_dataset(location, name, where);
  d.dims_ = dims_of(d.dataset_.get(), where);
  if (d.dims_.empty()) throw Failure(where + " is a scalar, expected rows");
  return d;
}

std::size_t RowDataset::record_size() const {
  std::size_t n = 1;
  for (std::size_t i = 1; i < dims_.size(); ++i) n *= dims_[i];
  return n;
}

void RowDataset::grow_to(hsize_t rows) {
  if (rows <= dims_[0]) return;
  std::vector<hsize_t> dims = dims_;
  dims[0] = rows;
  check(H5Dset_extent(dataset_.get(), dims.data()), "cannot extend", where_);
  dims_ = dims;
}

void RowDataset::write_rows(hsize_t first, hsize_t count, hid_t mem_type, const void* data) {
  std::vector<hsize_t> offset(dims_.size(), 0), block = dims_;
  offset[0] = first;
  block[0] = count;
  write_block(dataset_.get(), offset, block, mem_type, data, where_);
}

void RowDataset::read_rows(hsize_t first, hsize_t count, hid_t mem_type, void* out) const {
  std::vector<hsize_t> offset(dims_.size(), 0), block = dims_;
  offset[0] = first;
  block[0] = count;
  read_block(dataset_.get(), offset, block, mem_type, out, where_);
}

}  // namespace tomorig::storage::h5
