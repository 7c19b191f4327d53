#pragma once
// The `spray-thesis` case (../shared/benchmarks/README.md, thesis Ch. 6-7): synthetic
// tomographic shadowgraphy. Four views of Table 7.2 (yaw -45/-20/+25/+45 deg, M ~ 0.9, f/22)
// with inline LED illumination image a droplet field - a hollow cone (Ch. 6) or a jet in
// cross-flow (Ch. 7) - with a log-normal size distribution (5-100 um, Sauter mean ~25 um).
// Each droplet's shadow is a slightly transmitting disc (tau from the Mie model, kerosene in
// the 514 nm LED) blurred by each camera's depth-dependent Gaussian PSF chi(z) and integrated
// over the pixels; shadows multiply. The bright field carries a vignetting fall-off and a
// pulse-to-pulse energy variation; the sensor adds shot and read noise. Everything is seeded.
//
//   sim::SprayOptions opt;  opt.reduced = true;  opt.seed = 3;
//   sim::SprayCase c = sim::make_spray_thesis_case(opt);
//   sim::SpraySet s = sim::render_spray_set(c, 0);   // frames + droplets with visibility truth
//
// PSF: chi_c(z) is the half-width (s = exp(-2 r^2 / chi^2), Eq. 6.1) of the whole system as a
// knife edge measures it in the camera image, pixel integration included, in object-space um:
// the optics blur with sigma = sqrt((chi/2)^2 - p^2/12) for a pixel of p um.
#include <cstdint>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/optics/visibility.h"

namespace tomorig::sim {

enum class SprayPattern { hollow_cone, jet_in_crossflow };
// "hollow-cone" | "jet-in-crossflow" (the truth's flow name); the words a user writes are
// config's (config::SprayPattern), which rig/ maps onto this enum.
std::string to_string(SprayPattern p);

struct SprayOptions {
  bool reduced = false;  // 640 x 540 px with a 4x larger pixel pitch (same field), for tests
  std::uint64_t seed = 1;
  SprayPattern pattern = SprayPattern::jet_in_crossflow;
  int droplets = 0;             // per set; 0: 3000 (full) or 800 (reduced)
  double d_median_um = 14.0;    // log-normal number distribution: median and log-sigma give a
  double d_log_sigma = 0.5;     // Sauter mean of exp(ln 14 + 2.5 * 0.25) = 26 um
  double d_min_um = 5.0, d_max_um = 100.0;
  double dt_us = 1.7;           // pulse separation (Sect. 7.3)
  double bright_fraction = 0.05;  // bright field at 5 % of the 16-bit full scale (Sect. 7.3)
  double vignetting = 0.15;       // bright-field fall-off at the image corner
  // Pulse-to-pulse LED energy, 1 sigma (relative). Flat-fielding leaves it in the image, so it
  // adds to the bright-field noise and the threshold of visibility: kept small, as the thesis's
  // thresholds (0.980-0.988, Sect. 7.3.3) imply.
  double pulse_jitter = 0.005;
  // LED pulse B's mean energy relative to pulse A (1: equal). Below 1 it stands for an LED
  // whose second pulse sags (the spray quick-look flags a 20 % drop, issue 20).
  double pulse_b_energy = 1.0;
  bool noise = true;
  // Threads for rendering (OpenMP); 0: the default. Never changes the images.
  int threads = 0;

  void validate() const;  // bad_input naming the field
};

struct SprayCamera {
  std::string id;
  double yaw_deg = 0;
  int width = 0, height = 0;
  double pixel_pitch_um = 0;  // sensor pixel
  double magnification = 0;   // at the origin
  double f_number = 22;
  double noise_sigma = 0;     // relative noise of the bright field (sets the threshold 1 - 2 sigma)
  double gain_counts_per_e = 0;
  double threshold_value() const { return 1.0 - 2.0 * noise_sigma; }  // of visibility
  std::vector<optics::ChiSample> chi;  // the PSF truth over world z (13 depths, 0.75 mm apart)
  calibration::PinholeCamera pinhole = calibration::PinholeCamera::yawed(0.0, 100.0, 6.5, 111.0, 2560, 2160);
};

struct SprayCase {
  std::string name = "spray-thesis";
  SprayOptions options;
  std::vector<SprayCamera> cameras;
  Vec3d volume_min, volume_max;  // the droplet volume, world mm
  optics::VisibilitySetup optics;  // the set-up the visibility model needs (liquid, LED, cameras)
};

struct Droplet {
  Vec3d a, b;           // world mm at exposures A and B
  double d_um = 0;
  // Per camera: the deepest point of this droplet's own noise-free, flat-fielded shadow
  // (1 = no shadow; pixel-integrated, at exposure A), and whether it reaches the camera's
  // threshold of visibility 1 - 2 sigma. Outside a camera's image: 1 and false.
  std::vector<double> min_intensity;
  std::vector<bool> visible;
  bool visible_all() const;
};

struct SpraySet {
  FrameSet frames;  // cameras x (A, B), Mono16
  std::vector<Droplet> droplets;
  std::vector<double> pulse_energy_a, pulse_energy_b;  // per camera, relative to 1
};

SprayCase make_spray_thesis_case(const SprayOptions& options);
// The droplets of set k (positions, sizes), without images or visibility.
std::vector<Droplet> spray_droplets(const SprayCase& c, std::uint64_t set_index);
SpraySet render_spray_set(const SprayCase& c, std::uint64_t set_index);
// Set k as a live rig triggers it, with an actual pulse separation `dt_ns` (jitter included):
// the droplets keep their mid-time positions and sizes, their half-displacements scale with
// dt_ns / the case's dt. With the case's own dt it equals render_spray_set(c, k) bit for bit.
SpraySet render_spray_set(const SprayCase& c, std::uint64_t set_index, std::int64_t dt_ns);
// A bright-field frame without spray (camera c, frame k of a bright-field series), with the
// same light, pulse variation and noise: for the threshold of visibility (Sect. 6.4).
Image render_bright_field(const SprayCase& c, std::size_t camera, std::uint64_t frame);
// A calibration image for the knife-edge PSF (Sect. 6.4): a back-lit photomask of bars, 1 mm
// clear and 1 mm chromium (5 % transmission) over a band 30 % of the image high, slanted by
// `slant_deg` from the world y axis, on the plane z = z_mm, seen through camera c's PSF at that
// depth (the image-space blur and pixel integration the droplets get), with the bright field
// and noise of frame `frame`.
Image render_spray_edge_target(const SprayCase& c, std::size_t camera, double z_mm, std::uint64_t frame,
                               double slant_deg = 4.0);
// A chessboard calibration image for the knife-edge PSF in voxel space (Sect. 6.4, 7.3.3): a
// back-lit photomask chessboard of `square_mm` squares (clear / chromium at 5 % transmission)
// filling the view on the plane z = z_mm, its lines turned by
// `rotation_deg` from the world x and y axes (a real board is never aligned exactly; the turn
// lets the edges sample every sub-voxel phase), a square corner at the origin; seen through
// camera c's PSF at that depth (the blur and pixel integration the droplets get), with the
// bright field and noise of frame `frame`.
Image render_spray_chessboard_target(const SprayCase& c, std::size_t camera, double z_mm, std::uint64_t frame,
                                     double square_mm = 2.0, double rotation_deg = 3.0);
// The PSF half-width of camera c at world depth z (object um), linearly interpolated in the
// truth samples (clamped at the ends).
double spray_chi_um(const SprayCamera& cam, double z_mm);

}  // namespace tomorig::sim
