#pragma once
// The sparse sample list of MENT (thesis Sect. 3.1.1): the voxel centres (one line-of-sight
// sample per voxel depth) that read > 0 in every camera, i.e. the MLOS support. Only
// these points can carry a non-zero product of pseudo-images (h_j is 0 where the thresholded
// image p_j is, Eq. 3.1), so MENT's sweeps visit them and nothing else. They are found once, by
// the MLOS support pass, and kept per block of z-slices with their image position in every
// camera packed into 32 bits (see CellCode). It is a sparse list of the support, not a volume.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "grid_projector.h"
#include "prepared_input.h"

namespace tomorig::recon::detail {

// A camera-sized float plane with a one-pixel border of zeros, so that bilinear reads and
// splats anywhere in the image span [-0.5, W - 0.5] need no bounds checks.
struct MentPlane {
  int width = 0, height = 0, stride = 0;
  std::vector<float> data;

  MentPlane() = default;
  MentPlane(int w, int h)
      : width(w), height(h), stride(w + 2), data(static_cast<std::size_t>(w + 2) * (h + 2), 0.0f) {}

  float& at(int x, int y) { return data[static_cast<std::size_t>(y + 1) * stride + x + 1]; }
  float at(int x, int y) const { return data[static_cast<std::size_t>(y + 1) * stride + x + 1]; }
};

// Bilinear read of the 2 x 2 cell whose top-left element is p[0].
inline float bilinear_read(const float* p, std::size_t stride, float ax, float ay) {
  const float top = p[0] + ax * (p[1] - p[0]);
  const float bottom = p[stride] + ax * (p[stride + 1] - p[stride]);
  return top + ay * (bottom - top);
}

// The adjoint of bilinear_read: `value` shared over the 2 x 2 cell with the same weights.
inline void bilinear_splat(float* p, std::size_t stride, float ax, float ay, float value) {
  const float bottom = ay * value, top = value - bottom;
  p[0] += top - ax * top;
  p[1] += ax * top;
  p[stride] += bottom - ax * bottom;
  p[stride + 1] += ax * bottom;
}

// A bilinear read position in a padded plane, in 32 bits: the offset of the top-left element of
// its 2 x 2 cell in the high bits, then the u and v fractions quantised to 2^bits steps (stored
// as the centre of their step, so the error is at most half a step: 1/512 px for planes up to
// 2^16 elements, 1/64 px for 1600 x 1200 px, 1/32 px up to 2^24 elements).
class CellCode {
 public:
  CellCode() = default;
  // Throws tomorig::Error (bad_input) for planes of more than 2^24 elements.
  explicit CellCode(std::size_t largest_plane);

  // False outside the image span of `plane`.
  bool encode(const MentPlane& plane, float u, float v, std::uint32_t& code) const {
    if (!(u >= -0.5f && u <= plane.width - 0.5f && v >= -0.5f && v <= plane.height - 0.5f)) return false;
    // u, v >= -0.5, so truncating u + 1 floors it without a libm call.
    const int x = static_cast<int>(u + 1.0f), y = static_cast<int>(v + 1.0f);
    const auto qx = static_cast<std::uint32_t>(std::min((u + 1.0f - static_cast<float>(x)) * steps_, steps_ - 0.5f));
    const auto qy = static_cast<std::uint32_t>(std::min((v + 1.0f - static_cast<float>(y)) * steps_, steps_ - 0.5f));
    const auto offset = static_cast<std::uint32_t>(y * plane.stride + x);
    code = offset << (2 * bits_) | qx << bits_ | qy;
    return true;
  }
  void decode(std::uint32_t code, std::uint32_t& offset, float& ax, float& ay) const {
    offset = code >> (2 * bits_);
    ax = static_cast<float>((code >> bits_) & mask_) * step_ + half_step_;
    ay = static_cast<float>(code & mask_) * step_ + half_step_;
  }
  float read(const MentPlane& plane, std::uint32_t code) const { return read(plane.data.data(), plane.stride, code); }
  float read(const float* plane, std::size_t stride, std::uint32_t code) const {
    std::uint32_t offset;
    float ax, ay;
    decode(code, offset, ax, ay);
    return bilinear_read(plane + offset, stride, ax, ay);
  }
  void splat(float* plane, std::size_t stride, std::uint32_t code, float value) const {
    std::uint32_t offset;
    float ax, ay;
    decode(code, offset, ax, ay);
    bilinear_splat(plane + offset, stride, ax, ay, value);
  }
  int fraction_bits() const { return bits_; }

 private:
  int bits_ = 8;
  std::uint32_t mask_ = 255;
  float steps_ = 256.0f, step_ = 1.0f / 256, half_step_ = 0.5f / 256;
};

// The samples of one block of kSlabSlices z-slices (support_scan.h), all voxel centres
// (`centres` of them; the count is kept so that samples between slices could follow them), in
// (j, k, i) order: by grid row, then slice, then x. Codes are sample-major:
// code[n * cameras + c].
struct MentSlab {
  std::uint32_t centres = 0;
  std::vector<std::uint32_t> code;
  std::vector<std::uint32_t> voxel;  // linear grid index of each voxel-centre sample
};

struct MentSamples {
  std::vector<MentSlab> slabs;  // one per block of kSlabSlices z-slices
  std::size_t samples = 0, centres = 0;
};

// Bytes the sample list holds per sample and per voxel-centre sample (for memory estimates).
double ment_bytes_per_sample(std::size_t cameras);
constexpr double kMentBytesPerCentre = 4.0;

// The MLOS support pass (support_scan.h): every voxel centre whose bilinear read of `measured`
// (the images thresholded at `threshold` x their maximum, zero-bordered) is > 0 in every
// camera, also at its quantised position; z-slices in parallel. Throws tomorig::Error
// (bad_input) as soon as the list outgrows `budget_bytes`.
MentSamples build_ment_samples(const PreparedInput& in, const GridProjector& projector,
                               const std::vector<MentPlane>& measured, const CellCode& codec, double threshold,
                               double budget_bytes);

}  // namespace tomorig::recon::detail
