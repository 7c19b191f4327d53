#pragma once
// The sparse machinery shared by FMART, SMART and MART (thesis Sect. 3.1.3): for every active
// voxel and camera, the offset of its p x p pixel patch in a padded image and the two LUT rows
// of its weights, stored camera by camera as contiguous arrays (structure of arrays), so that
// the projection (scatter) and the update (gather) stream through memory with no virtual calls,
// no exp() per weight and no allocation inside an iteration.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "grid_projector.h"
#include "prepared_input.h"
#include "weight_table.h"

namespace tomorig::recon::detail {

struct PixelResidual {
  double abs_difference = 0.0;  // sum |I - I~| over the image
  double measured = 0.0;        // sum I over the image
};

class SparseSystem {
 public:
  // index: the active voxels (ascending linear index); their image positions come from the
  // projector. patch: p; lut_steps: sub-pixel steps. `recycle` (may be null): a system no
  // longer needed, whose arrays (already touched memory) this one takes over; it is left empty.
  SparseSystem(const PreparedInput& in, const std::vector<std::uint32_t>& index, const GridProjector& projector,
               int patch, int lut_steps, SparseSystem* recycle = nullptr);

  // Memory estimate of a system of `voxels` voxels (index, intensity, scratch and per camera
  // offset + 2 LUT rows) plus its images, for the up-front check.
  static double estimate_bytes(const PreparedInput& in, std::size_t voxels, int patch, int threads);

  std::size_t voxels() const { return voxels_; }
  std::size_t cameras() const { return cams_.size(); }

  // I~ of camera c (Eq. 3.7) from intensities e, then the log-ratio image ln(I / I~) that the
  // update reads; returns the residual of this projection.
  PixelResidual project(std::size_t c, const float* e, int threads);
  // FMART/MART-by-camera update (Eq. 3.9): e_j *= exp(mu * sum_i w_ij ln R_i); returns the sum
  // over voxels of |1 - P_j|.
  double update(std::size_t c, float* e, float mu, int threads) const;
  // SMART: acc_j += sum_i w_ij ln R_i (the caller applies exp(mu * acc / cameras)).
  void accumulate(std::size_t c, float* acc, int threads) const;

  // Keeps only the voxels at positions `kept` (ascending), in that order.
  void compact(const std::vector<std::uint32_t>& kept, int threads);

  // Row-by-row (classical MART) access: the patch of voxel n in camera c.
  struct Patch {
    std::int32_t offset;  // padded-image index of the patch's first pixel
    const float* wu;      // p weights along u (axis-aligned PSF), else null
    const float* wv;      // p weights along v (axis-aligned PSF), else null
    const float* block;   // p x p weights, v-major (rotated PSF), else null
    int p;
    float weight(int a, int b) const { return block ? block[b * p + a] : wu[a] * wv[b]; }
  };
  Patch patch_of(std::size_t c, std::size_t n) const {
    const Camera& cam = cams_[c];
    if (cam.rotated)
      return {cam.offset[n], nullptr, nullptr,
              cam.block_weights.table() + static_cast<std::size_t>(cam.row_2d[n]) * patch_ * patch_, patch_};
    return {cam.offset[n], cam.u_weights.table() + static_cast<std::size_t>(cam.row_u[n]) * patch_,
            cam.v_weights.table() + static_cast<std::size_t>(cam.row_v[n]) * patch_, nullptr, patch_};
  }
  int patch() const { return patch_; }
  int stride(std::size_t c) const { return cams_[c].stride; }
  const std::vector<float>& measured(std::size_t c) const { return cams_[c].measured; }
  // Whether padded index `pixel` of camera c lies inside the image (not in the padding).
  bool inside(std::size_t c, std::int32_t pixel) const;

 private:
  SparseSystem() = default;  // the empty system a recycled one is left as

  struct Camera {
    int width = 0, height = 0, pad = 0, stride = 0;
    std::vector<float> measured;    // padded, 0 in the padding
    std::vector<float> projection;  // padded
    std::vector<float> log_ratio;   // padded, 0 in the padding: no information, no update
    std::vector<std::int32_t> offset;
    std::vector<std::uint16_t> row_u, row_v;  // axis-aligned PSF: LUT rows along u and v
    AxisWeights u_weights, v_weights;
    bool rotated = false;                     // rotated PSF: one 2-D LUT row per voxel instead
    std::vector<std::uint32_t> row_2d;
    PatchWeights block_weights;
  };
  // Calls kernel(w) with the camera's weight source (see sparse_system.cpp).
  template <class F>
  void with_weights(const Camera& cam, F&& kernel) const;

  int patch_ = 0;
  std::size_t voxels_ = 0;
  std::vector<Camera> cams_;
  std::vector<std::vector<float>> scratch_;  // per extra thread: a private projection image
};

}  // namespace tomorig::recon::detail
