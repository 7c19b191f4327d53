#pragma once
// Particle images: pixel-integrated 2-D Gaussians (thesis Table 3.1: diameter 4 sigma = 3 px),
// accumulated into a float image of sensor counts before any noise or quantisation.
//
// A particle imaged at (u, v) with peak I0 (the peak of the continuous Gaussian) adds to
// pixel (i, j), which spans [i - 1/2, i + 1/2] x [j - 1/2, j + 1/2],
//   I0 * 2 pi sigma^2 * Gx(i) * Gy(j),  Gx(i) = (erf((i + 1/2 - u) / (sqrt2 sigma)) -
//                                              erf((i - 1/2 - u) / (sqrt2 sigma))) / 2,
// so its total over the plane is I0 * 2 pi sigma^2 and its centroid is (u, v).
#include <span>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/simulators/light_sheet.h"

namespace tomorig::sim {

struct ParticleImageOptions {
  double sigma_px = 0.75;       // Gaussian sigma; Table 3.1's 3 px diameter is 4 sigma
  double peak_counts = 1000.0;  // peak of a fully lit particle image, in counts
  // Half-width of the window rendered around each particle, in sigma. At 5 sigma the part of
  // the Gaussian left out is < 1e-6 of its integral; below ~4.5 it exceeds 1e-4.
  double window_sigmas = 5.0;
  int threads = 0;  // OpenMP threads; 0: the OpenMP default. The result never depends on it.

  // Throws tomorig::Error (bad_input) naming the field that is out of range.
  void validate() const;
};

// One particle image on the sensor: centre in pixels and peak intensity in counts.
struct ParticleImage {
  Vec2d centre;
  double peak = 0.0;
};

// Adds `particles` to `signal` (an f32 image, counts). Parts outside the image are dropped;
// non-finite centres are skipped. Deterministic: every pixel sums its particles in the order
// given, whatever the number of threads (work is split by image rows, never racing on pixels).
void render_particle_images(std::span<const ParticleImage> particles, const ParticleImageOptions& options,
                            Image& signal);

// Projects world points (mm) through `camera`, scales each peak by the light sheet at its z,
// and renders them with render_particle_images.
void render_particles(const calibration::CameraModel& camera, std::span<const Vec3d> particles,
                      const LightSheet& sheet, const ParticleImageOptions& options, Image& signal);

}  // namespace tomorig::sim
