#include "correlation/window_lag_sums.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace tomorig::piv::detail {
namespace {

// Slots an A entry touches (P, QA, its sums) and a B entry touches (QB, its sums).
constexpr int kSlotsA = kSlotQB, kSlotsB = kLagSlots - kSlotQB;
// An A entry's stored values: its 27 lag products, then A itself for the first QA slots; the
// other slots' values are A or A^2 (the weight table is 0 in the unused slots).
constexpr int kStoredA = 32;
static_assert(kSlotQA == 27 && kStoredA <= kSlotSumA && kSlotsA == 2 * kStoredA && kSlotsB == 32);

// Lag component of slot l (0..26) along an axis: x fastest, as lag_index.
int lag_along(int l, int axis) { return axis == 0 ? l % 3 - 1 : axis == 1 ? (l / 3) % 3 - 1 : l / 9 - 1; }

// Per position i in the window, the weight each slot's voxel gets along this axis.
void weight_table(const std::vector<float>& w, int axis, std::vector<float>& table) {
  const int n = static_cast<int>(w.size());
  table.assign(static_cast<std::size_t>(n) * kLagSlots, 0.0f);
  auto wrap = [n](int i) { return ((i % n) + n) % n; };
  for (int i = 0; i < n; ++i) {
    float* row = table.data() + static_cast<std::size_t>(i) * kLagSlots;
    for (int l = 0; l < 27; ++l) {
      const int d = lag_along(l, axis);
      // P: only where x + s stays in the window along this axis (no wrap): the product over
      // the axes leaves out exactly the (voxel, lag) pairs whose lag wraps around the window.
      row[kSlotP + l] = (i + d >= 0 && i + d < n) ? w[i] * w[i + d] : 0.0f;
      row[kSlotQA + l] = w[i] * w[wrap(i + d)];
      row[kSlotQB + l] = w[i] * w[wrap(i - d)];
    }
    row[kSlotSumA] = row[kSlotSumB] = 1.0f;
    row[kSlotW2A] = row[kSlotW2A2] = row[kSlotW2B] = row[kSlotW2B2] = w[i] * w[i];
  }
}

// One thread's stored values of the current row's A entries (kStoredA each); they grow to the
// longest row's and are reused.
struct RowEntries {
  std::vector<float> va;
};

struct Geometry {
  Int3 window, step, nodes;
  int y_end, z_end;  // voxels that some window covers
  int ix0, ix1;      // the windows along x of this task, [ix0, ix1)
};

// Row y of plane z: every window ix0..ix1 - 1 along x gets its row sum (slot values times the x
// weights), or is marked unused when no entry of the row lies in it.
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] void row_sums(
    const OccupiedVoxels& oa, const VolumeView& b, const OccupiedVoxels& ob, const Geometry& g, int y, int z,
    const float* table_x, RowEntries& e, float* rows, std::uint8_t* used) {
  const int x_begin = g.ix0 * g.step.x, x_end = (g.ix1 - 1) * g.step.x + g.window.x;
  // This row's entries of a and b within the slab's x range.
  const std::size_t row = y + static_cast<std::size_t>(b.ny) * z;
  const OccupiedVoxels::RowEntry* first_a = oa.row_entries.data() + oa.row_offsets[row];
  const OccupiedVoxels::RowEntry* last_a = oa.row_entries.data() + oa.row_offsets[row + 1];
  const OccupiedVoxels::RowEntry* first_b = ob.row_entries.data() + ob.row_offsets[row];
  const OccupiedVoxels::RowEntry* last_b = ob.row_entries.data() + ob.row_offsets[row + 1];
  while (first_a < last_a && first_a->x < x_begin) ++first_a;
  while (last_a > first_a && (last_a - 1)->x >= x_end) --last_a;
  while (first_b < last_b && first_b->x < x_begin) ++first_b;
  while (last_b > first_b && (last_b - 1)->x >= x_end) --last_b;
  const std::size_t na = static_cast<std::size_t>(last_a - first_a), nb = static_cast<std::size_t>(last_b - first_b);
  if (e.va.size() < na * kStoredA) e.va.resize(na * kStoredA);
  const bool lags_inside = y >= 1 && y + 1 < b.ny && z >= 1 && z + 1 < b.nz;
  const std::size_t sy = static_cast<std::size_t>(b.nx), sz = sy * static_cast<std::size_t>(b.ny);
  for (std::size_t n = 0; n < na; ++n) {
    const int x = first_a[n].x;
    const float av = first_a[n].value;
    float* v = e.va.data() + n * kStoredA;
    if (lags_inside && x >= 1 && x + 1 < b.nx) {
      // The 27 lag products A(x) B(x + s), B read dense.
      const float* centre = b.data + b.linear(x, y, z);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
          const float* r = centre + dz * static_cast<std::ptrdiff_t>(sz) + dy * static_cast<std::ptrdiff_t>(sy);
          float* out = v + kSlotP + 3 * ((dy + 1) + 3 * (dz + 1));
          out[0] = av * r[-1];
          out[1] = av * r[0];
          out[2] = av * r[1];
        }
    } else {
      // On the volume's faces: the lags outside the volume wrap in every window holding the
      // voxel (their P weight is 0); 0 stands in for them.
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy, zz = z + dz;
            const bool in = xx >= 0 && yy >= 0 && zz >= 0 && xx < b.nx && yy < b.ny && zz < b.nz;
            v[kSlotP + (dx + 1) + 3 * ((dy + 1) + 3 * (dz + 1))] = in ? av * b.data[b.linear(xx, yy, zz)] : 0.0f;
          }
    }
    for (int l = kSlotQA; l < kStoredA; ++l) v[l] = av;
  }
  std::size_t lo_a = 0, hi_a = 0, lo_b = 0, hi_b = 0;
  for (int ix = g.ix0; ix < g.ix1; ++ix) {
    const int x0 = ix * g.step.x, x1 = x0 + g.window.x;
    while (lo_a < na && first_a[lo_a].x < x0) ++lo_a;
    while (hi_a < na && first_a[hi_a].x < x1) ++hi_a;
    while (lo_b < nb && first_b[lo_b].x < x0) ++lo_b;
    while (hi_b < nb && first_b[hi_b].x < x1) ++hi_b;
    const std::size_t r = static_cast<std::size_t>(ix - g.ix0) * g.y_end + y;
    if (lo_a >= hi_a && lo_b >= hi_b) {
      used[r] = 0;
      continue;
    }
    used[r] = 1;
    alignas(64) float acc[kLagSlots] = {};
    for (std::size_t n = lo_a; n < hi_a; ++n) {
      const float* v = e.va.data() + n * kStoredA;
      const float* w = table_x + static_cast<std::size_t>(first_a[n].x - x0) * kLagSlots;
      const float av = first_a[n].value, av2 = av * av;
#pragma omp simd
      for (int l = 0; l < kStoredA; ++l) acc[l] += v[l] * w[l];
#pragma omp simd
      for (int l = kStoredA; l < kSlotsA; ++l) acc[l] += (l == kSlotW2A2 ? av2 : av) * w[l];
    }
    for (std::size_t n = lo_b; n < hi_b; ++n) {
      const float* w = table_x + static_cast<std::size_t>(first_b[n].x - x0) * kLagSlots;
      const float bv = first_b[n].value, bv2 = bv * bv;
#pragma omp simd
      for (int l = kSlotQB; l < kLagSlots; ++l) acc[l] += (l == kSlotW2B2 ? bv2 : bv) * w[l];
    }
    std::copy(acc, acc + kLagSlots, rows + r * kLagSlots);
  }
}

// Window column (ix, iy) in plane z: its rows' sums times the y weights, added times the z
// weights to every window along z that holds the plane.
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] void column_sums(
    const Geometry& g, int ix, int iy, int z, const float* rows, const std::uint8_t* used, const float* table_y,
    const float* table_z, float* sums) {
  alignas(64) float acc[kLagSlots] = {};
  bool any = false;
  const int y0 = iy * g.step.y;
  for (int j = 0; j < g.window.y; ++j) {
    const std::size_t r = static_cast<std::size_t>(ix - g.ix0) * g.y_end + (y0 + j);
    if (!used[r]) continue;
    any = true;
    const float* v = rows + r * kLagSlots;
    const float* w = table_y + static_cast<std::size_t>(j) * kLagSlots;
#pragma omp simd
    for (int l = 0; l < kLagSlots; ++l) acc[l] += v[l] * w[l];
  }
  if (!any) return;
  const int iz_first = std::max(0, (z - g.window.z + g.step.z) / g.step.z);
  const int iz_last = std::min(g.nodes.z - 1, z / g.step.z);
  for (int iz = iz_first; iz <= iz_last; ++iz) {
    const int k = z - iz * g.step.z;
    if (k < 0 || k >= g.window.z) continue;
    float* out = sums + (static_cast<std::size_t>(ix) +
                         static_cast<std::size_t>(g.nodes.x) * (iy + static_cast<std::size_t>(g.nodes.y) * iz)) *
                            kLagSlots;
    const float* w = table_z + static_cast<std::size_t>(k) * kLagSlots;
#pragma omp simd
    for (int l = 0; l < kLagSlots; ++l) out[l] += acc[l] * w[l];
  }
}

}  // namespace

void window_lag_sums(const OccupiedVoxels& oa, const VolumeView& b, const OccupiedVoxels& ob, Int3 window,
                     Int3 step, Int3 nodes, const std::vector<float>& wx, const std::vector<float>& wy,
                     const std::vector<float>& wz, int threads, WindowLagSums& out) {
  const Geometry whole{window, step, nodes, (nodes.y - 1) * step.y + window.y, (nodes.z - 1) * step.z + window.z, 0,
                       nodes.x};
  out.nodes = nodes;
  const std::size_t node_count = static_cast<std::size_t>(nodes.x) * nodes.y * nodes.z;
  out.sums.resize(node_count * kLagSlots);
  std::vector<float> table_x, table_y, table_z;
  weight_table(wx, 0, table_x);
  weight_table(wy, 1, table_y);
  weight_table(wz, 2, table_z);
  // Tasks: slabs of windows along x, each summed through every plane by one thread with no
  // barrier between planes (a thread of a loaded machine that waits at a barrier per plane
  // waits for the slowest, 2 x 160 times). A slab's rows reach W - S voxels into its
  // neighbour's: a few per cent of the entries are listed twice, none summed twice.
  const int slab = std::max(1, 2 * ((window.x + step.x - 1) / step.x));
  const int tasks = (nodes.x + slab - 1) / slab;
  out.rows.resize(static_cast<std::size_t>(threads));
  out.row_used.resize(static_cast<std::size_t>(threads));
  float* sums = out.sums.data();
  const long long columns_per_plane = static_cast<long long>(nodes.y);
#pragma omp parallel num_threads(threads)
  {
#pragma omp for schedule(static)
    for (long long n = 0; n < static_cast<long long>(node_count * kLagSlots); ++n) sums[n] = 0.0f;
    const int t = omp_get_thread_num();
    std::vector<float>& rows = out.rows[t];
    std::vector<std::uint8_t>& used = out.row_used[t];
    rows.resize(static_cast<std::size_t>(slab) * whole.y_end * kLagSlots);
    used.resize(static_cast<std::size_t>(slab) * whole.y_end);
    RowEntries entries;
#pragma omp for schedule(dynamic, 1)
    for (int task = 0; task < tasks; ++task) {
      Geometry g = whole;
      g.ix0 = task * slab;
      g.ix1 = std::min(nodes.x, g.ix0 + slab);
      for (int z = 0; z < g.z_end; ++z) {
        for (int y = 0; y < g.y_end; ++y)
          row_sums(oa, b, ob, g, y, z, table_x.data(), entries, rows.data(), used.data());
        for (long long c = 0; c < columns_per_plane; ++c)
          for (int ix = g.ix0; ix < g.ix1; ++ix)
            column_sums(g, ix, static_cast<int>(c), z, rows.data(), used.data(), table_y.data(), table_z.data(), sums);
      }
    }
  }
}

}  // namespace tomorig::piv::detail
