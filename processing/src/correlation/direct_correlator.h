#pragma once
// Sparse direct correlation of the deformation passes (thesis Sect. 2.5, Discetti & Astarita):
// after deformation the residual displacement is sub-voxel, so only the correlation values at
// lags -1..1 (and the peak's outer neighbours) are needed, and a particle volume is mostly
// empty. The occupied voxels of a volume (above a small fraction of its maximum) are listed
// once per pass in blocks of the window step, shared by the overlapping windows. The sums of
// Eq. 2.16 over every window come from one separable contraction (window_lag_sums.h); each
// window then adds its shell's lag products (the lags that wrap around it) and evaluates
// Eq. 2.16 with the same weights, means, energies and circular indexing as the FFT path, so
// where both find the same peak they give the same coefficients (up to rounding and the
// dropped near-zero voxels).
#include <cstdint>
#include <vector>

#include "correlation/fft_correlator.h"
#include "correlation/volume_view.h"
#include "tomorig/processing/correlation/correlation_options.h"

namespace tomorig::piv::detail {

// Voxels whose magnitude exceeds `relative_threshold` times the volume's largest magnitude,
// bucketed in blocks of `block` voxels per axis (scan order inside a block), and by row.
struct OccupiedVoxels {
  struct Entry {
    std::uint16_t x, y, z;
    float value;
  };
  struct RowEntry {
    int x;
    float value;
  };
  Int3 block, blocks;                 // block size, block counts per axis
  std::vector<std::size_t> offsets;   // blocks + 1 offsets into entries
  std::vector<Entry> entries;
  // The same voxels by row (y, z), x ascending: row r = y + ny z holds
  // row_entries[row_offsets[r] .. row_offsets[r + 1]).
  std::vector<std::size_t> row_offsets;
  std::vector<RowEntry> row_entries;
  // Per block, its entries on each of its six faces (x = first, x = last, y = first, ... of
  // the block; face f of block b is face_entries[f][face_offsets[f][b] .. face_offsets[f][b + 1])):
  // where windows start and end on block borders, a window's shell is the union of its
  // border blocks' faces, so its wrapped lags visit only those entries.
  std::vector<std::size_t> face_offsets[6];
  std::vector<Entry> face_entries[6];
  double occupied_fraction = 0;       // entries / voxels
  // list_occupied's per-block-slab row lists (memory reused from one listing to the next).
  std::vector<std::vector<RowEntry>> slab_entries;
};
// Fills `out`, reusing its memory (one list per volume for a whole correlation); the face lists
// only with `faces` (the wrapped lags read them from volume a's lists alone). `largest` is the
// volume's largest magnitude (largest_magnitude(v), or known from where the volume was made).
void list_occupied(const VolumeView& v, Int3 block, float relative_threshold, float largest, int threads,
                   OccupiedVoxels& out, bool faces);

// Calls f(i, j, k, value) for every entry of `o` inside the window of `w` voxels at `start`
// (i, j, k in window coordinates), visiting only the blocks the window touches.
template <class F>
void for_each_in_window(const OccupiedVoxels& o, Int3 start, Int3 w, F&& f) {
  if (start.x + w.x <= 0 || start.y + w.y <= 0 || start.z + w.z <= 0) return;
  auto first_block = [](int s, int size) { return s <= 0 ? 0 : s / size; };
  auto last_block = [](int s, int size, int blocks) { return s / size < blocks - 1 ? s / size : blocks - 1; };
  const int bx0 = first_block(start.x, o.block.x), bx1 = last_block(start.x + w.x - 1, o.block.x, o.blocks.x);
  const int by0 = first_block(start.y, o.block.y), by1 = last_block(start.y + w.y - 1, o.block.y, o.blocks.y);
  const int bz0 = first_block(start.z, o.block.z), bz1 = last_block(start.z + w.z - 1, o.block.z, o.blocks.z);
  for (int bz = bz0; bz <= bz1; ++bz)
    for (int by = by0; by <= by1; ++by)
      for (int bx = bx0; bx <= bx1; ++bx) {
        const std::size_t b = bx + static_cast<std::size_t>(o.blocks.x) * (by + static_cast<std::size_t>(o.blocks.y) * bz);
        for (std::size_t e = o.offsets[b]; e < o.offsets[b + 1]; ++e) {
          const OccupiedVoxels::Entry& v = o.entries[e];
          const int i = v.x - start.x, j = v.y - start.y, k = v.z - start.z;
          // (Unsigned: one test each for below 0 and beyond the window.)
          if (static_cast<unsigned>(i) >= static_cast<unsigned>(w.x) ||
              static_cast<unsigned>(j) >= static_cast<unsigned>(w.y) || static_cast<unsigned>(k) >= static_cast<unsigned>(w.z))
            continue;
          f(i, j, k, v.value);
        }
      }
}

// The fraction of a volume's largest magnitude below which a voxel counts as empty. A voxel at
// 0.3 % of the brightest adds at most that fraction of a bright voxel's product to any lag, far
// below the peak's curvature that the sub-voxel fit reads; at 1e-3 the lists also held the faint
// floor of FMART volumes (4.5 % of the voxels listed instead of 2.7 % at 0.05 ppp, 14.5 % instead
// of 8.9 % at 0.10 ppp) for no change in any accuracy figure (docs/correlation.md, "Speed", sixth
// round).
inline constexpr float kOccupiedThreshold = 3e-3f;

// Per face list of OccupiedVoxels (same order), kFaceSlots products per entry: the entry's
// value times b at its partner across a window of `window` voxels (the FFT's circular lag over
// that face), at the 3 x 3 lags of the two other axes (slot (du + 1) + 3 (dv + 1), u before v
// in x, y, z order); 0 where the partner lies outside b.
inline constexpr int kFaceSlots = 9;
struct FaceProducts {
  Int3 window;
  std::vector<float> values[6];
};
void face_products(const OccupiedVoxels& oa, const VolumeView& vb, Int3 window, int threads, FaceProducts& out);

class DirectCorrelator {
 public:
  DirectCorrelator(Int3 window, WindowWeighting weighting, double gaussian_sigma);

  struct Scratch {
    StageSeconds seconds;
    // correlate_around's window entries (window coordinates) and per-axis tables, memory
    // reused per thread.
    std::vector<OccupiedVoxels::Entry> window_a, window_b;
    struct AxisTables {
      std::vector<float> plus, minus;
      std::vector<int> b;
    } axes[3];
  };

  // The same window from its contracted sums (window_lag_sums.h: `sums` its kLagSlots floats)
  // plus the lag products of its shell's entries of `oa`, whose lags wrap around the window;
  // the peak's outer neighbours beyond +-1, when needed, from the window's entries. `fallback`
  // is false when the peak lies within the lags searched; otherwise the caller correlates
  // this window by FFT.
  // `faces` (of oa and vb for this window size), where given, supply the shell's products of
  // the entries on one window face only, for windows on block borders.
  WindowPeak correlate_from_sums(const float* sums, const OccupiedVoxels& oa, const VolumeView& vb,
                                 const OccupiedVoxels& ob, Int3 start, Scratch& scratch, bool& fallback,
                                 const FaceProducts* faces = nullptr) const;

  // A pass without deformation (the windows of a and b start at start_a and start_b, which may
  // differ by an integer offset): Eq. 2.16 at the 27 lags around `centre` (a lag of the FFT's
  // plane, from the binned pre-search) and the peak's outer neighbours, from the windows' own
  // entries (at 50 % overlap each voxel lies in 8 windows: nothing worth sharing). The peak's
  // lag is absolute (centre included). Voxels outside a volume count as 0, as for the FFT;
  // `fallback` as for correlate_from_sums, and also when the lags would reach the plane's wrap.
  WindowPeak correlate_around(const OccupiedVoxels& oa, const OccupiedVoxels& ob, const VolumeView& vb, Int3 start_a,
                              Int3 start_b, Int3 centre, Scratch& scratch, bool& fallback) const;

  const std::vector<float>& weights_x() const { return wx_; }
  const std::vector<float>& weights_y() const { return wy_; }
  const std::vector<float>& weights_z() const { return wz_; }

 private:
  Int3 window_;
  std::vector<float> wx_, wy_, wz_;      // separable weights per axis
  // The same, circularly padded by 2 on both sides (element i + 2 is the weight at i, for
  // i = -2 .. n + 1): the lags' weights without a wrap test per lag.
  std::vector<float> px_, py_, pz_;
  double weight_energy_ = 0;             // sum of w^2 over the window
  // Circular autocorrelation of the weights per axis, K(d) for d = -2..2 at index d + 2.
  double kx_[5], ky_[5], kz_[5];
  // The same at every lag 0 .. W - 1 (circular), for correlate_around's centres.
  std::vector<float> kx_full_, ky_full_, kz_full_;

  // Adds the wrapped lag products of one shell entry (window coordinates i, j, k) into p4.
  void add_shell_entry(const OccupiedVoxels::Entry& v, int i, int j, int k, Int3 start, const VolumeView& vb,
                       bool inside, float (*p4)[4]) const;

  // R(s) of Eq. 2.16 at `count` (<= 3) lags with one component +-2, circular in the window,
  // over every entry of the window.
  void outer_lags(const OccupiedVoxels& oa, const VolumeView& vb, const OccupiedVoxels& ob, Int3 start,
                  const int lags[][3], int count, double mean_a, double mean_b, double* out) const;
};

}  // namespace tomorig::piv::detail
