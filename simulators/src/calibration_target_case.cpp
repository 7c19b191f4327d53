// calib-thesis geometry and truth: the board, the four spray-thesis views, the traverse planes
// with their seeded positioning errors, and the true (distorting) camera models.
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/simulators/calibration_target.h"
#include "tomorig/simulators/random.h"

namespace tomorig::sim {

namespace {

constexpr std::uint64_t kStageStream = 0x7374616765ULL;  // "stage"

constexpr double kYawsDeg[] = {-45.0, -20.0, 25.0, 45.0};  // thesis Table 7.2
// A 100 mm lens at magnification 0.9: the pinhole's image distance is f (1 + M) = 190 mm and
// the object distance f (1 + 1/M) = 211 mm (their ratio is the magnification).
constexpr double kMagnification = 0.9;
constexpr double kImageDistanceMm = 100.0 * (1 + kMagnification);
constexpr double kObjectDistanceMm = kImageDistanceMm / kMagnification;
constexpr double kFullPitchUm = 6.5;  // 2560 x 2160 sCMOS
// The views aim 1.4 mm above the board's centre so that its top edge (with a row of outer
// squares) is always in the picture: at magnification 0.9 the 15.6 mm tall field is shorter
// than the 16.5 mm of printed squares, so some bottom corners leave the image, as in the
// thesis (volume 16.5 x 15.8 mm). The detector then identifies the corners by the top edge.
constexpr double kAimAboveCentreMm = 1.4;

calibration::PinholeCamera aimed_camera(double yaw_deg, double pitch_um, int width, int height, const Vec3d& aim) {
  const calibration::PinholeCamera base = calibration::PinholeCamera::yawed(
      yaw_deg, kImageDistanceMm, pitch_um, kObjectDistanceMm, width, height);
  calibration::PinholeParameters p = base.parameters();
  // yawed() looks at the world origin; shift the view to look at `aim` instead: t' = t - R aim.
  const auto& R = p.R;
  p.t = {p.t.x - (R[0] * aim.x + R[1] * aim.y + R[2] * aim.z), p.t.y - (R[3] * aim.x + R[4] * aim.y + R[5] * aim.z),
         p.t.z - (R[6] * aim.x + R[7] * aim.y + R[8] * aim.z)};
  return calibration::PinholeCamera(p);
}

}  // namespace

void CalibTargetOptions::validate() const {
  auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0; };
  if (!finite_nonneg(stage_error_scale))
    throw bad_input(fmt::format("calib-thesis: stage_error_scale = {} must be >= 0", stage_error_scale));
  if (!std::isfinite(distortion_corner_px) || std::abs(distortion_corner_px) > 50)
    throw bad_input(fmt::format("calib-thesis: distortion_corner_px = {} must be within +-50", distortion_corner_px));
  if (!finite_nonneg(blur_sigma_px))
    throw bad_input(fmt::format("calib-thesis: blur_sigma_px = {} must be >= 0", blur_sigma_px));
  for (double v : {light_counts, dark_counts, background_counts})
    if (!finite_nonneg(v) || v > 65535)
      throw bad_input(fmt::format("calib-thesis: grey levels must be within [0, 65535], got {}", v));
  if (!(light_counts > dark_counts))
    throw bad_input(fmt::format("calib-thesis: light_counts = {} must exceed dark_counts = {}", light_counts, dark_counts));
}

Vec2d TargetCamera::distort(const Vec2d& u) const {
  const auto& p = pinhole.parameters();
  const double half_diag = 0.5 * std::hypot(width, height);
  const double dx = u.x - p.cx, dy = u.y - p.cy;
  const double f = 1 + k1 * (dx * dx + dy * dy) / (half_diag * half_diag);
  return {p.cx + dx * f, p.cy + dy * f};
}

Vec2d TargetCamera::undistort(const Vec2d& d) const {
  const auto& p = pinhole.parameters();
  const double half_diag = 0.5 * std::hypot(width, height);
  // Fixed-point iteration; the distortion is mild (|k1| << 1), so it contracts fast.
  Vec2d u = d;
  for (int k = 0; k < 6; ++k) {
    const double dx = u.x - p.cx, dy = u.y - p.cy;
    const double f = 1 + k1 * (dx * dx + dy * dy) / (half_diag * half_diag);
    u = {p.cx + (d.x - p.cx) / f, p.cy + (d.y - p.cy) / f};
  }
  return u;
}

Vec2d TargetCamera::project(const Vec3d& world) const { return distort(pinhole.project(world)); }

Vec3d TargetCamera::back_project(const Vec2d& pixel, double world_z) const {
  return pinhole.back_project(undistort(pixel), world_z);
}

Vec3d CalibTargetCase::corner_world(int i, int j, std::size_t plane) const {
  const TargetPlane& p = planes.at(plane);
  return {i * board.square_mm + p.offset_mm.x, j * board.square_mm + p.offset_mm.y, p.z_nominal_mm + p.offset_mm.z};
}

Vec2d CalibTargetCase::corner_pixel(std::size_t camera, int i, int j, std::size_t plane) const {
  return cameras.at(camera).project(corner_world(i, j, plane));
}

CalibTargetCase make_calib_thesis_case(const CalibTargetOptions& options) {
  options.validate();
  CalibTargetCase c;
  c.options = options;
  c.board = {22, 21, 0.75};
  const int scale = options.reduced ? 4 : 1;
  const int width = 2560 / scale, height = 2160 / scale;
  const double pitch_um = kFullPitchUm * scale;
  const Vec3d aim{0.5 * (c.board.inner_corners_x - 1) * c.board.square_mm,
                  0.5 * (c.board.inner_corners_y - 1) * c.board.square_mm - kAimAboveCentreMm, 0.0};
  for (std::size_t k = 0; k < std::size(kYawsDeg); ++k) {
    TargetCamera cam{fmt::format("cam{}", k + 1), kYawsDeg[k], width, height, pitch_um,
                     aimed_camera(kYawsDeg[k], pitch_um, width, height, aim), 0.0};
    // Alternate the sign so that the views disagree (a common distortion would partly look
    // like a change of magnification to every camera alike).
    const double corner_px = options.distortion_corner_px / scale * (k % 2 == 0 ? -1.0 : 1.0);
    cam.k1 = corner_px / (0.5 * std::hypot(width, height));
    c.cameras.push_back(std::move(cam));
  }
  // Table 6.3: |dx| < ~1 um, |dy| up to ~8 um, |dz| up to ~22 um; the case draws uniformly
  // within +-2, +-8 and +-22 um per plane.
  std::mt19937_64 engine(derive_seed(options.seed, {kStageStream}));
  auto uniform = [&](double half_um) { return (2 * unit_double(engine) - 1) * half_um * options.stage_error_scale * 1e-3; };
  for (int k = 0; k < 7; ++k) {
    TargetPlane p;
    p.z_nominal_mm = -4.5 + 1.5 * k;
    p.offset_mm.x = uniform(2.0);
    p.offset_mm.y = uniform(8.0);
    p.offset_mm.z = uniform(22.0);
    c.planes.push_back(p);
  }
  return c;
}

}  // namespace tomorig::sim
