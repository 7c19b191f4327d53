#include "prepared_input.h"

#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/core.h>
#include <omp.h>

#include "tomorig/core/error.h"

namespace tomorig::recon::detail {
namespace {

constexpr double kDefaultWeightSigma = kDefaultPsfSigmaPx;  // psf_model.h

void check_grid(const VoxelGrid& g) {
  if (g.nx <= 0 || g.ny <= 0 || g.nz <= 0)
    throw bad_input(fmt::format("reconstruction: grid of {} x {} x {} voxels: every dimension must be > 0", g.nx,
                                g.ny, g.nz));
  if (!(g.voxel_size > 0) || !std::isfinite(g.voxel_size))
    throw bad_input(fmt::format("reconstruction: grid voxel_size = {} mm must be > 0", g.voxel_size));
  if (!std::isfinite(g.origin.x) || !std::isfinite(g.origin.y) || !std::isfinite(g.origin.z))
    throw bad_input("reconstruction: grid origin is not finite");
  // Sparse volumes index voxels with 32 bits.
  if (g.voxel_count() >= std::numeric_limits<std::uint32_t>::max())
    throw bad_input(fmt::format("reconstruction: grid of {} x {} x {} = {} voxels is too large: at most {} voxels "
                                "(32-bit indices); use larger voxels or a smaller region",
                                g.nx, g.ny, g.nz, g.voxel_count(), std::numeric_limits<std::uint32_t>::max() - 1));
}

template <typename T>
void convert(const Image& image, std::size_t camera, CameraImage& out) {
  for (int y = 0; y < out.height; ++y) {
    const T* row = image.row<T>(y);
    float* dst = out.pixels.data() + static_cast<std::size_t>(y) * out.width;
    for (int x = 0; x < out.width; ++x) {
      const float v = static_cast<float>(row[x]);
      if (!std::isfinite(v))
        throw bad_input(fmt::format("reconstruction: camera {} image has a non-finite pixel ({}) at x = {}, y = {}: "
                                    "replace NaN/Inf pixels (e.g. by 0) before reconstructing",
                                    camera, v, x, y));
      dst[x] = v > 0 ? v : 0.0f;
    }
  }
}

CameraImage to_camera_image(const Image& image, std::size_t camera) {
  CameraImage out;
  out.width = image.width();
  out.height = image.height();
  out.pixels.assign(static_cast<std::size_t>(out.width) * out.height, 0.0f);
  switch (image.type()) {
    case SampleType::u8: convert<std::uint8_t>(image, camera, out); break;
    case SampleType::u16: convert<std::uint16_t>(image, camera, out); break;
    case SampleType::f32: convert<float>(image, camera, out); break;
  }
  double sum = 0;
  std::size_t nonzero = 0;
  for (float v : out.pixels)
    if (v > 0) {
      sum += v;
      ++nonzero;
    }
  if (nonzero == 0)
    throw bad_input(fmt::format("reconstruction: camera {} image is all zero (or negative): there is nothing to "
                                "reconstruct; check the exposure, the background subtraction or the camera order",
                                camera));
  const float scale = static_cast<float>(static_cast<double>(nonzero) / sum);
  for (float& v : out.pixels) {
    v *= scale;
    out.max = std::max(out.max, v);
  }
  out.nonzero_fraction = static_cast<double>(nonzero) / static_cast<double>(out.pixels.size());
  return out;
}

}  // namespace

PreparedInput prepare_input(const ReconstructionInput& input, const ReconstructionOptions& options) {
  const std::size_t n = input.cameras.size();
  if (n == 0) throw bad_input("reconstruction: no cameras: give one camera model per image");
  if (input.images.size() != n)
    throw bad_input(fmt::format("reconstruction: {} camera models (calibration) but {} images: give exactly one "
                                "image per calibrated camera, in the same order",
                                n, input.images.size()));
  if (!input.sensor_sizes.empty() && input.sensor_sizes.size() != n)
    throw bad_input(fmt::format("reconstruction: the calibration lists {} sensor sizes for {} cameras",
                                input.sensor_sizes.size(), n));
  if (!input.psf.empty() && input.psf.size() != n)
    throw bad_input(fmt::format("reconstruction: {} PSF models for {} cameras: give one per camera or none",
                                input.psf.size(), n));
  check_grid(input.grid);

  PreparedInput out;
  out.grid = input.grid;
  out.threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  for (std::size_t c = 0; c < n; ++c) {
    if (input.cameras[c] == nullptr) throw bad_input(fmt::format("reconstruction: camera {} has no model", c));
    const Image& image = input.images[c];
    if (image.empty() || image.width() <= 0 || image.height() <= 0)
      throw bad_input(fmt::format("reconstruction: camera {} image is empty", c));
    if (!input.sensor_sizes.empty()) {
      const SensorSize& s = input.sensor_sizes[c];
      if (s.width != image.width() || s.height != image.height())
        throw bad_input(fmt::format("reconstruction: camera {} image is {} x {} px but its calibration is for {} x {} "
                                    "px: use the calibration made for these images (or the uncropped images)",
                                    c, image.width(), image.height(), s.width, s.height));
    }
    out.cameras.push_back(input.cameras[c]);
    out.psf.push_back(input.psf.empty() ? PsfModel::constant(kDefaultWeightSigma) : input.psf[c]);
    out.psf.back().validate(fmt::format("reconstruction: camera {} PSF", c));
  }
  // Converted after the cheap checks so that a count mismatch is reported before a pixel scan.
  out.images.resize(n);
  for (std::size_t c = 0; c < n; ++c) out.images[c] = to_camera_image(input.images[c], c);
  return out;
}

double image_bytes(const PreparedInput& in, int copies_per_camera, int pad) {
  double bytes = 0;
  for (const CameraImage& im : in.images)
    bytes += static_cast<double>(im.width + 2 * pad) * (im.height + 2 * pad) * sizeof(float) * copies_per_camera;
  return bytes;
}

}  // namespace tomorig::recon::detail
