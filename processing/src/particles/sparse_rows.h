#pragma once
// Neighbour look-up in a sparse volume without a dense copy: a directory of where each
// (j, k) row starts in the sorted index list. A neighbour lies in one of 9 rows, and within a
// row the entries are sorted by i, so walking a row in order, one forward-only cursor per
// neighbouring row finds every neighbour without searching.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "tomorig/core/volume.h"

namespace tomorig::particles::detail {

struct Voxel {
  int i = 0, j = 0, k = 0;
};

class SparseRows {
 public:
  // `index`: ascending linear indices into `grid` (a SparseVolume's), kept alive by the caller.
  SparseRows(const VoxelGrid& grid, const std::vector<std::uint32_t>& index)
      : nx_(grid.nx), ny_(grid.ny), nz_(grid.nz), index_(index.data()),
        row_start_(static_cast<std::size_t>(grid.ny) * grid.nz + 1, 0) {
    for (std::uint32_t idx : index) ++row_start_[idx / static_cast<std::uint32_t>(nx_) + 1];
    for (std::size_t r = 1; r < row_start_.size(); ++r) row_start_[r] += row_start_[r - 1];
  }

  Voxel voxel_of(std::size_t entry) const {
    const std::uint32_t idx = index_[entry];
    const std::uint32_t row = idx / static_cast<std::uint32_t>(nx_);
    return {static_cast<int>(idx - row * static_cast<std::uint32_t>(nx_)), static_cast<int>(row % static_cast<std::uint32_t>(ny_)),
            static_cast<int>(row / static_cast<std::uint32_t>(ny_))};
  }

  std::size_t row_count() const { return row_start_.size() - 1; }
  // Entries [first, last) of row `row` (row = j + ny * k).
  std::pair<std::uint32_t, std::uint32_t> row_range(std::size_t row) const { return {row_start_[row], row_start_[row + 1]}; }

  // Calls f(entry, voxel, neighbours, count) for every entry of row `row` (row = j + ny * k),
  // in ascending i, where neighbours[0..count) are the stored voxels adjacent to it: the 26
  // sharing a face, edge or corner, or only the 6 sharing a face when connectivity == 6.
  // One cursor per neighbouring row only moves forward, so a row costs O(its entries + the
  // neighbouring rows' entries), without searching.
  template <class F>
  void visit_row(std::size_t row, int connectivity, F&& f) const {
    const std::uint32_t first = row_start_[row], last = row_start_[row + 1];
    if (first == last) return;
    const bool faces_only = connectivity == 6;
    const int j = static_cast<int>(row % static_cast<std::size_t>(ny_)), k = static_cast<int>(row / static_cast<std::size_t>(ny_));
    struct Cursor {
      std::uint32_t at, end, base;
      int reach;  // how far in i a neighbour may lie in this row
      bool centre;
    };
    Cursor cursors[9];
    int used = 0;
    for (int dk = -1; dk <= 1; ++dk) {
      if (k + dk < 0 || k + dk >= nz_) continue;
      for (int dj = -1; dj <= 1; ++dj) {
        if (j + dj < 0 || j + dj >= ny_) continue;
        const bool centre = dj == 0 && dk == 0;
        if (faces_only && dj != 0 && dk != 0) continue;
        const std::size_t r = static_cast<std::size_t>(j + dj) + static_cast<std::size_t>(ny_) * (k + dk);
        if (row_start_[r] == row_start_[r + 1]) continue;
        cursors[used++] = {row_start_[r], row_start_[r + 1], static_cast<std::uint32_t>(r * nx_),
                           faces_only && !centre ? 0 : 1, centre};
      }
    }
    std::uint32_t neighbours[26];
    const std::uint32_t base = static_cast<std::uint32_t>(row * nx_);
    for (std::uint32_t e = first; e < last; ++e) {
      const int i = static_cast<int>(index_[e] - base);
      int count = 0;
      for (int c = 0; c < used; ++c) {
        Cursor& cur = cursors[c];
        const std::uint32_t lo = cur.base + static_cast<std::uint32_t>(std::max(i - cur.reach, 0));
        const std::uint32_t hi = cur.base + static_cast<std::uint32_t>(i + cur.reach);
        while (cur.at < cur.end && index_[cur.at] < lo) ++cur.at;
        for (std::uint32_t m = cur.at; m < cur.end && index_[m] <= hi; ++m)
          if (!cur.centre || m != e) neighbours[count++] = m;
      }
      f(static_cast<std::size_t>(e), Voxel{i, j, k}, static_cast<const std::uint32_t*>(neighbours), count);
    }
  }

 private:
  int nx_, ny_, nz_;
  const std::uint32_t* index_;
  std::vector<std::uint32_t> row_start_;
};

}  // namespace tomorig::particles::detail
