#pragma once
// The input contract of every reconstructor, checked once at the top of reconstruct(), and
// the images converted to what the kernels read: float, contiguous, normalised so that the
// mean of the non-zero pixels is 1 (thesis Sect. 3.1.3), negative values clipped to 0.
#include <cstddef>
#include <vector>

#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::recon::detail {

struct CameraImage {
  int width = 0, height = 0;
  std::vector<float> pixels;  // width * height, row-major, normalised
  float max = 0.0f;           // after normalisation
  double nonzero_fraction = 0.0;

  float at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

struct PreparedInput {
  std::vector<CameraImage> images;
  std::vector<const calibration::CameraModel*> cameras;
  VoxelGrid grid;
  std::vector<PsfModel> psf;  // one per camera
  int threads = 1;

  std::size_t camera_count() const { return cameras.size(); }
};

// Throws tomorig::Error (bad_input) for: no cameras; camera and image counts that differ; a
// null camera; an empty image; images whose size differs from the calibration's sensor size; a
// bad grid or one with more than 2^32 - 1 voxels; a PSF count or PSF that is wrong; a NaN or
// infinite pixel; an image that is all zero.
PreparedInput prepare_input(const ReconstructionInput& input, const ReconstructionOptions& options);

// Bytes of images the kernels keep per camera (padded float copies), for memory estimates.
double image_bytes(const PreparedInput& in, int copies_per_camera, int pad);

}  // namespace tomorig::recon::detail
