#pragma once
// Reconstruction quality Q (thesis Eq. 3.14): the normalised correlation between a
// reconstruction E and the ground truth G,
//   Q = sum(E G) / sqrt(sum(E^2) sum(G^2)),
// over the whole grid (global) and as the mean over cubic windows (windowed; the thesis
// used 64^3 windows at 32-voxel steps: 15 x 15 x 4 windows on 512 x 512 x 160).
#include <cstddef>
#include <vector>

#include "tomorig/core/volume.h"

namespace tomorig::quality {

struct WindowOptions {
  int size = 64;  // window edge, voxel
  int step = 32;  // distance between window origins, voxel
  // Throws tomorig::Error (bad_input) naming the field that is out of range.
  void validate() const;
};

// Window origins along an axis of `length` voxels: 0, step, 2 step, ... while the window fits;
// when they leave voxels uncovered at the far end, one more window flush with that end, so
// every voxel is judged (none is added when length - size is a multiple of step, as in the
// thesis grid). An axis shorter than `size` gets one window spanning it.
std::vector<int> window_origins(int length, const WindowOptions& options);

struct QualityFactor {
  double global = 0.0;          // Eq. 3.14 over the whole grid; 0 if either volume is empty
  double windowed = 0.0;        // mean of Q over the windows that hold signal
  std::size_t windows = 0;      // windows on the grid (nwx * nwy * nwz)
  std::size_t windows_used = 0; // windows where E or G is non-zero; a window with signal in
                                // only one of them counts with Q = 0
  int windows_x = 0, windows_y = 0, windows_z = 0;
  std::vector<double> window_q; // per window, x fastest; NaN where neither volume has signal
};

// Q of `reconstruction` against `truth`, both sparse on the same grid. Zeros not stored
// contribute nothing, so the result equals the dense computation. One merge pass over both
// index lists; OpenMP over fixed chunks, summed in a fixed order, so the result never
// depends on the thread count (threads = 0: the OpenMP default).
// Throws tomorig::Error (bad_input) if the grids differ or a volume is malformed.
QualityFactor quality_factor(const SparseVolume& reconstruction, const SparseVolume& truth,
                             const WindowOptions& windows = {}, int threads = 0);

}  // namespace tomorig::quality
