// Opening a version-2 results file for appending (see results_file_open.h).
#include "results_file_open.h"

#include <algorithm>

#include "h5_datasets.h"
#include "results_file_layout.h"
#include "results_layout.h"

namespace tomorig::storage::results_detail {
namespace fs = std::filesystem;
namespace layout = results_layout;
namespace v2 = results_layout_v2;

std::optional<OpenFile> OpenFile::open(const fs::path& path) {
  h5::PropertyList fapl(h5::check(H5Pcreate(H5P_FILE_ACCESS), "cannot create", "a file access list"));
  h5::check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), "cannot configure",
            "a file access list");
  const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDWR | H5F_ACC_SWMR_WRITE, fapl.get());
  if (id < 0) return std::nullopt;
  OpenFile f;
  f.file = h5::File(id);
  h5::Group sets = h5::open_group(id, layout::kSets, "/sets");
  const hid_t g = sets.get();
  f.complete = h5::RowDataset::open(g, v2::kComplete, "/sets/complete");
  f.set_index = h5::RowDataset::open(g, v2::kSetIndex, "/sets/set_index");
  f.dt = h5::RowDataset::open(g, v2::kDt, "/sets/dt_ns");
  f.seconds = h5::RowDataset::open(g, v2::kSeconds, "/sets/seconds");
  f.completed = h5::RowDataset::open(g, v2::kCompleted, "/sets/completed_utc");
  f.report_span = h5::RowDataset::open(g, v2::kReportSpan, "/sets/report_span");
  f.report_text = h5::RowDataset::open(g, v2::kReportText, "/sets/report_text");
  f.displacement = h5::RowDataset::open(g, layout::kDisplacement, "/sets/displacement_voxel");
  f.velocity = h5::RowDataset::open(g, layout::kVelocity, "/sets/velocity_m_s");
  f.status = h5::RowDataset::open(g, layout::kStatus, "/sets/status");
  f.peak = h5::RowDataset::open(g, layout::kPeak, "/sets/peak");
  // A row half-written before a failure stays unused (its completion byte is 0): append after
  // the longest dataset.
  for (h5::RowDataset* r : f.rows()) f.next_row = std::max(f.next_row, r->rows());
  const hsize_t readable = std::min(f.complete.rows(), f.set_index.rows());
  if (readable > 0) {
    std::vector<std::uint8_t> done(readable);
    std::vector<std::uint64_t> index(readable);
    f.complete.read_rows(0, readable, H5T_NATIVE_UINT8, done.data());
    f.set_index.read_rows(0, readable, H5T_NATIVE_UINT64, index.data());
    for (hsize_t r = 0; r < readable; ++r)
      if (done[r] == 1) f.commit(index[r], r);
  }
  h5::Group stats = h5::open_group(id, layout::kStatistics, "/statistics");
  const hid_t s = stats.get();
  f.stats_sets = h5::open_dataset(s, v2::kStatisticsSets, "/statistics/sets");
  f.valid_count = h5::open_dataset(s, layout::kValidCount, "/statistics/valid_count");
  f.mean_displacement = h5::open_dataset(s, layout::kMeanDisplacement, "/statistics/mean_displacement_voxel");
  f.mean_velocity = h5::open_dataset(s, layout::kMeanVelocity, "/statistics/mean_velocity_m_s");
  f.rms_velocity = h5::open_dataset(s, layout::kRmsVelocity, "/statistics/rms_velocity_m_s");
  f.reynolds = h5::open_dataset(s, layout::kReynoldsStress, "/statistics/reynolds_stress_m2_s2");
  return f;
}

void write_whole(hid_t dataset, hid_t mem_type, const void* data, const char* where) {
  h5::check(H5Dwrite(dataset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "cannot write", where);
}

}  // namespace tomorig::storage::results_detail
