#pragma once
// The voxels of a grid row that read > 0 in every camera's thresholded image: the MLOS support
// test, shared by MLOS (which keeps the product of the reads) and MENT's sample list (which
// keeps the positions). Exactly the voxels a dense pass sampling every voxel in every camera
// would keep, at a few CPU cycles per voxel and camera:
//
// - Cameras are tried most selective first (smallest fraction of reachable cells).
// - The reach test is a dense pass over the row per camera, 16 voxels at a time with AVX-512
//   (runtime dispatch; scalar otherwise, same results): positions from the row's lattice
//   segments (GridProjector::row_segments, the arithmetic of row()), then one bit of a packed
//   reach mask per voxel (a gather; 1 bit per cell, ~240 kB for 1600 x 1200 px, so it stays
//   in cache). Branchy scalar code that jumped over runs of empty cells visited 5x fewer
//   voxels and was no faster: with a quarter of the cells reachable the runs are short and
//   every decision is a mispredicted branch.
// - Cameras after the first only pass over the span between the first and last voxel still
//   alive, and the scan stops at a camera that leaves no voxel alive. Once the survivors are
//   fewer than a quarter of that span, the later cameras test the listed survivors instead.
// - Only the voxels reachable in every camera are read (bilinear, in order()), and those whose
//   reads are all > 0 are kept.
// - Before any of that, a coarse test per 2 x 2 x 2 block of voxels: the block's centre against
//   each camera's reach mask dilated by the largest distance between a voxel's image and its
//   block centre's (from the projector's slopes). It is conservative, so the support is the
//   same; it only lets the passes above start from the blocks that may hold survivors, an
//   eighth of the tests per camera for the rest. Cameras without a lattice (exact projection)
//   or whose dilation would exceed kMaxCoarseRadius cells are left out of it.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "grid_projector.h"
#include "prepared_input.h"

namespace tomorig::recon::detail {

// One camera's image with pixels below the threshold set to 0, a one-pixel border of zeros (so
// bilinear reads anywhere in the image span [-0.5, W - 0.5] need no bounds check) and the
// reach mask: cell (x, y) is reachable if one of the pixels a bilinear read at
// x = floor(u + 1), y = floor(v + 1) uses is non-empty.
struct ThresholdedImage {
  int width = 0, height = 0, stride = 0;  // stride = width + 2
  std::vector<float> pixels;              // (width + 2) x (height + 2), padded
  std::vector<std::uint8_t> reach;        // same layout
  double reach_fraction = 0.0;
  // The reach mask packed: cell n is bit n % 32 of word n / 32.
  std::vector<std::uint32_t> reach_bits;

  ThresholdedImage(const CameraImage& image, double threshold);

  bool in_span(float u, float v) const {
    return u >= -0.5f && u <= static_cast<float>(width) - 0.5f && v >= -0.5f && v <= static_cast<float>(height) - 0.5f;
  }
  // The padded cell of (u, v), known to be in the span.
  std::size_t cell(float u, float v) const {
    return static_cast<std::size_t>(static_cast<int>(v + 1.0f)) * static_cast<std::size_t>(stride) +
           static_cast<std::size_t>(static_cast<int>(u + 1.0f));
  }
  // Bilinear read at (u, v), 0 outside the span; no branch.
  float read(float u, float v) const {
    const float lo = -0.5f, hu = static_cast<float>(width) - 0.5f, hv = static_cast<float>(height) - 0.5f;
    const float cu = std::min(std::max(u, lo), hu), cv = std::min(std::max(v, lo), hv);
    const float s = sample(cu, cv);
    return cu == u && cv == v ? s : 0.0f;
  }
  // Bilinear read at (u, v), known to be in the span.
  float sample(float u, float v) const {
    const int x = static_cast<int>(u + 1.0f), y = static_cast<int>(v + 1.0f);
    const float ax = u + 1.0f - static_cast<float>(x), ay = v + 1.0f - static_cast<float>(y);
    const float* p = pixels.data() + static_cast<std::size_t>(y) * stride + x;
    const float top = p[0] + ax * (p[1] - p[0]);
    const float bottom = p[stride] + ax * (p[stride + 1] - p[stride]);
    return top + ay * (bottom - top);
  }
};

// Callers scan blocks of this many z-slices row by row across the block (j outer, k inner):
// grid row j of neighbouring slices projects to the same few image rows in every camera, so
// the image reads of the block stay in cache instead of sweeping the whole images per slice.
constexpr int kSlabSlices = 8;

// For tests: false forces the scalar reach pass even where AVX-512 is available (default
// true). Both give the same voxels and values.
void allow_vector_reach_pass(bool allow);

class SupportScanner {
 public:
  // Thresholds the images (pixels below threshold x the image maximum are empty).
  SupportScanner(const PreparedInput& in, const GridProjector& projector, double threshold);

  // Per-thread working memory of scan(), allocated once.
  struct Row {
    std::vector<float> u, v;         // cameras x nx: positions, valid at the voxels tested
    std::vector<float> product;      // nx: product of the reads, valid at the survivors
    std::vector<int> alive;          // the survivors, ascending
    std::vector<std::uint32_t> reachable;  // nx: 1 while the voxel is reachable in every camera so far
    std::vector<float> u0, du, v0, dv;     // the current camera's row segments
    // Work counters, for profiling: voxels tested per camera of order(), and voxels reachable
    // in every camera (then read).
    std::vector<std::uint64_t> tested;
    std::uint64_t reached = 0;
    // The coarse test's results for the last kCoarseRows super-rows (slot K % kCoarseRows),
    // with their (J, K) keys, and its scratch: block-centre positions, the centre line's segments.
    std::vector<std::uint32_t> coarse, coarse_voxels;  // per slot: per block, and spread to the voxels
    std::vector<long long> coarse_key;
    std::vector<int> coarse_span;  // per slot: first and last + 1 voxel that may be a survivor
    std::vector<float> coarse_u, coarse_v, centre_segments;
  };
  Row make_row() const;

  // Voxels (i, j, k) that read > 0 in every camera: their count; indices in row.alive, and for
  // each of them row.u/v[c * nx + i] (every camera) and row.product[i] (the product of the
  // reads, multiplied in order()). Allocation-free.
  int scan(int j, int k, Row& row) const;

  const std::vector<std::size_t>& order() const { return order_; }  // most selective first
  const ThresholdedImage& image(std::size_t c) const { return images_[c]; }
  std::size_t cameras() const { return images_.size(); }
  // How many cameras take part in the coarse block test.
  std::size_t coarse_cameras() const {
    return static_cast<std::size_t>(std::count_if(coarse_.begin(), coarse_.end(), [](const CoarseCamera& c) { return c.enabled; }));
  }

 private:
  // A coarse test dilates by at most this many cells; beyond, it would reject too little.
  static constexpr int kMaxCoarseRadius = 3;
  // Super-rows remembered per thread: callers scan kSlabSlices slices per grid row.
  static constexpr std::size_t kCoarseRows = kSlabSlices / 2;
  struct CoarseCamera {
    bool enabled = false;
    std::vector<std::uint32_t> bits;  // the reach mask dilated for the coarse test, packed
  };
  struct CoarseRow {
    const std::uint32_t* mask;  // per voxel of the row: 1 if its block may hold survivors
    int first, last;            // the voxels outside [first, last) are not survivors
  };
  int coarse_nx() const;
  CoarseRow coarse_row(int big_j, int big_k, Row& row) const;

  const GridProjector& projector_;
  int nx_ = 0;
  std::vector<ThresholdedImage> images_;
  std::vector<std::size_t> order_;
  std::vector<CoarseCamera> coarse_;
  bool any_coarse_ = false;
};

}  // namespace tomorig::recon::detail
