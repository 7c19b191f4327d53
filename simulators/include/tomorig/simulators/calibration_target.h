#pragma once
// The `calib-thesis` case (benchmarks README, thesis Sect. 6.3): a chessboard target moved by
// a traverse through 7 planes and imaged by the 4 spray-thesis views, with the traverse
// positioning errors of Table 6.3's size, optional mild radial lens distortion, optical blur
// and sensor noise. Everything is seeded; the truth (true cameras, nominal plane heights and
// true plane offsets) comes with it.
//
//   sim::CalibTargetOptions opt;  opt.reduced = true;  opt.seed = 3;
//   sim::CalibTargetCase c = sim::make_calib_thesis_case(opt);
//   Image img = sim::render_target_view(c, camera, plane);   // u16, Mono16
//
// World frame = the target's frame (docs/calibration.md, "Chessboard targets"): inner corner
// (i, j) of the board at nominal plane k sits at (i * square, j * square, z_k); x to the right
// and y downwards as the cameras see it, z away from the cameras. The traverse really puts it
// at that point + offset_k (offset in mm).
#include <cstdint>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::sim {

struct CalibTargetOptions {
  // 640 x 540 pixels with a 4x larger pixel pitch (same field of view) instead of 2560 x 2160.
  bool reduced = false;
  std::uint64_t seed = 1;  // stage errors and noise
  // Scales the seeded stage errors (1: Table 6.3's size, up to 2/8/22 um in x/y/z; 0: none).
  double stage_error_scale = 1.0;
  // Radial distortion at the image corner, pixels of the full-size sensor (scaled with the
  // pixel pitch for the reduced variant). 0: a distortion-free pinhole camera.
  double distortion_corner_px = 0.6;
  bool noise = true;             // shot + read noise
  // Gaussian optical blur, pixels of the rendered sensor: f/22 diffraction at M = 0.9 is ~9 um,
  // 1.4 px of the 6.5 um sensor; the reduced variant keeps the look of the full images (same
  // blur in pixels) rather than undersampling it.
  double blur_sigma_px = 1.4;
  double light_counts = 30000;   // light squares (dark squares: dark_counts), 16-bit counts
  double dark_counts = 2500;
  double background_counts = 16000;  // outside the printed area of the target

  // Throws tomorig::Error (bad_input) naming the field.
  void validate() const;
};

// A true camera: pinhole plus radial distortion about the principal point,
// u_d = c + (u - c) (1 + k1 r^2), r = |u - c| / (half the image diagonal).
struct TargetCamera {
  std::string id;  // "cam1".."cam4"
  double yaw_deg = 0;
  int width = 0, height = 0;
  double pixel_pitch_um = 0;
  calibration::PinholeCamera pinhole;
  double k1 = 0;  // pixels of distortion at r = 1 divided by the half diagonal

  Vec2d project(const Vec3d& world) const;
  // The world point on the plane z = world_z seen at `pixel` (inverts the distortion).
  Vec3d back_project(const Vec2d& pixel, double world_z) const;
  Vec2d distort(const Vec2d& undistorted) const;
  Vec2d undistort(const Vec2d& distorted) const;
};

struct TargetPlane {
  double z_nominal_mm = 0;  // where the traverse was told to go
  Vec3d offset_mm;          // where it really went, minus the nominal position (the truth)
};

struct CalibTargetCase {
  std::string name = "calib-thesis";
  CalibTargetOptions options;
  calibration::ChessboardSpec board;  // 22 x 21 inner corners at 0.75 mm
  std::vector<TargetCamera> cameras;
  std::vector<TargetPlane> planes;    // 7 planes, z = -4.5 .. +4.5 mm

  // True world position (mm) of inner corner (i, j) at plane k.
  Vec3d corner_world(int i, int j, std::size_t plane) const;
  // Where camera c truly sees inner corner (i, j) at plane k (pixels).
  Vec2d corner_pixel(std::size_t camera, int i, int j, std::size_t plane) const;
};

CalibTargetCase make_calib_thesis_case(const CalibTargetOptions& options);

// The Mono16 image camera `camera` records of plane `plane`: the board (dark/light squares
// with one row of squares beyond the outer inner corners, then background) integrated over
// each pixel's area, blurred and digitised with noise seeded from (seed, camera, plane).
Image render_target_view(const CalibTargetCase& c, std::size_t camera, std::size_t plane);

}  // namespace tomorig::sim
