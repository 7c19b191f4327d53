// spray-thesis: cameras, PSF truth and droplet fields (spray.h). Rendering: spray_render.cpp.
#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"
#include "tomorig/simulators/random.h"
#include "tomorig/simulators/spray.h"

namespace tomorig::sim {
namespace {

constexpr std::uint64_t kDropletStream = 0x64726f706c6574ULL;  // "droplet"

// Table 7.2 and Fig. 7.9's shape: chi grows away from each camera's focus, faster for the
// inner views (the 200 mm lenses). chi(z) = sqrt(chi0^2 + (g (z - z_focus))^2), object um.
struct ViewSpec {
  const char* id;
  double yaw_deg, magnification, focal_mm, chi0_um, z_focus_mm, growth_um_per_mm, noise_sigma;
};
constexpr ViewSpec kViews[] = {
    {"cam1", -45.0, 0.85, 105.0, 42.0, 0.3, 8.9, 0.010},
    {"cam2", -20.0, 0.95, 200.0, 40.0, -0.4, 12.2, 0.006},
    {"cam3", 25.0, 0.93, 200.0, 41.0, 0.5, 12.0, 0.006},
    {"cam4", 45.0, 0.91, 105.0, 44.0, -0.2, 8.5, 0.010},
};

double normal(std::mt19937_64& rng) {
  // Box-Muller from unit_double: the same numbers with every standard library.
  const double u1 = std::max(unit_double(rng), 1e-300), u2 = unit_double(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace

std::string to_string(SprayPattern p) { return p == SprayPattern::hollow_cone ? "hollow-cone" : "jet-in-crossflow"; }

void SprayOptions::validate() const {
  if (droplets < 0 || droplets > 1000000) throw bad_input(fmt::format("spray: droplets = {} must be in [0, 1e6]", droplets));
  if (!(d_min_um > 0 && d_max_um > d_min_um && d_max_um <= 500))
    throw bad_input(fmt::format("spray: droplet sizes [{}, {}] um must satisfy 0 < min < max <= 500", d_min_um, d_max_um));
  if (!(d_median_um > 0) || !(d_log_sigma >= 0))
    throw bad_input("spray: d_median_um must be > 0 and d_log_sigma >= 0");
  if (!(dt_us >= 0)) throw bad_input(fmt::format("spray: dt_us = {} must be >= 0", dt_us));
  if (!(bright_fraction > 0 && bright_fraction <= 0.9))
    throw bad_input(fmt::format("spray: bright_fraction = {} must be in (0, 0.9]", bright_fraction));
  if (!(vignetting >= 0 && vignetting < 0.9)) throw bad_input(fmt::format("spray: vignetting = {} must be in [0, 0.9)", vignetting));
  if (!(pulse_b_energy > 0 && pulse_b_energy <= 2))
    throw bad_input(fmt::format("spray: pulse_b_energy = {} must be in (0, 2]", pulse_b_energy));
  if (!(pulse_jitter >= 0 && pulse_jitter < 0.5)) throw bad_input(fmt::format("spray: pulse_jitter = {} must be in [0, 0.5)", pulse_jitter));
}

bool Droplet::visible_all() const {
  return !visible.empty() && std::all_of(visible.begin(), visible.end(), [](bool v) { return v; });
}

double spray_chi_um(const SprayCamera& cam, double z_mm) {
  const auto& s = cam.chi;
  if (z_mm <= s.front().z_mm) return s.front().chi_um;
  if (z_mm >= s.back().z_mm) return s.back().chi_um;
  std::size_t i = 1;
  while (s[i].z_mm < z_mm) ++i;
  const double t = (z_mm - s[i - 1].z_mm) / (s[i].z_mm - s[i - 1].z_mm);
  return s[i - 1].chi_um + t * (s[i].chi_um - s[i - 1].chi_um);
}

SprayCase make_spray_thesis_case(const SprayOptions& options) {
  options.validate();
  SprayCase c;
  c.options = options;
  if (c.options.droplets == 0) c.options.droplets = options.reduced ? 800 : 3000;
  // 16 x 13 x 10 mm (Sect. 7.7).
  c.volume_min = {-8.0, -6.5, -5.0};
  c.volume_max = {8.0, 6.5, 5.0};
  const double pitch = options.reduced ? 26.0 : 6.5;  // sCMOS 6.5 um; reduced: 4x
  const int width = options.reduced ? 640 : 2560, height = options.reduced ? 540 : 2160;
  const double level = options.bright_fraction * 65535.0;
  c.optics.liquid = optics::Liquid::kerosene();
  c.optics.spectrum = optics::LedSpectrum{};  // 514 nm, 37 nm FWHM
  c.optics.d_max_um = options.d_max_um;
  for (const ViewSpec& v : kViews) {
    SprayCamera cam;
    cam.id = v.id;
    cam.yaw_deg = v.yaw_deg;
    cam.width = width;
    cam.height = height;
    cam.pixel_pitch_um = pitch;
    cam.magnification = v.magnification;
    cam.f_number = 22.0;
    cam.noise_sigma = v.noise_sigma;
    // Shot noise sets the bright field's relative noise: sigma^2 = gain / level.
    cam.gain_counts_per_e = v.noise_sigma * v.noise_sigma * level;
    // The pixel's own blur is part of chi; it must stay below it.
    const double object_pixel = pitch / v.magnification;
    for (int k = 0; k < 13; ++k) {
      const double z = -4.5 + 0.75 * k;
      const double g = v.growth_um_per_mm * (z - v.z_focus_mm);
      const double chi = std::sqrt(v.chi0_um * v.chi0_um + g * g);
      if (chi / 2.0 <= object_pixel / std::sqrt(12.0))
        throw bad_input(fmt::format("spray: {}'s chi {} um is below its pixel's own blur", v.id, chi));
      cam.chi.push_back({z, chi});
    }
    cam.pinhole = calibration::PinholeCamera::yawed(v.yaw_deg, v.focal_mm, pitch, v.focal_mm / v.magnification, width, height);
    optics::CameraOptics o;
    o.id = cam.id;
    o.f_number = cam.f_number;
    o.magnification = cam.magnification;
    o.noise_sigma = cam.noise_sigma;
    o.chi = cam.chi;
    c.optics.cameras.push_back(o);
    c.cameras.push_back(std::move(cam));
  }
  c.optics.validate();
  return c;
}

std::vector<Droplet> spray_droplets(const SprayCase& c, std::uint64_t set_index) {
  const SprayOptions& o = c.options;
  std::mt19937_64 rng(derive_seed(o.seed, {kDropletStream, set_index}));
  const Vec3d lo = c.volume_min, hi = c.volume_max;
  const auto inside = [&](const Vec3d& p) {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  };
  const double dt_s = o.dt_us * 1e-6;
  std::vector<Droplet> out;
  out.reserve(static_cast<std::size_t>(o.droplets));
  while (out.size() < static_cast<std::size_t>(o.droplets)) {
    Droplet drop;
    do drop.d_um = std::exp(std::log(o.d_median_um) + o.d_log_sigma * normal(rng));
    while (drop.d_um < o.d_min_um || drop.d_um > o.d_max_um);
    Vec3d p, v;  // mid-time position (mm) and velocity (m/s = mm/ms)
    if (o.pattern == SprayPattern::hollow_cone) {
      // A simplex swirl nozzle 10 mm above the volume on the y axis, spray angle 63 deg
      // (Sect. 6.2): droplets on the cone's sheet, thickening downstream, moving along it
      // with a swirl; small droplets slow down faster.
      const double half_angle = 31.5 * M_PI / 180.0;
      const double y = lo.y + (hi.y - lo.y) * unit_double(rng);
      const double along = y + 10.0;
      const double r = along * std::tan(half_angle) + (0.15 + 0.04 * along) * normal(rng);
      const double phi = 2.0 * M_PI * unit_double(rng);
      p = {r * std::cos(phi), y, r * std::sin(phi)};
      const double speed = 12.0 + 10.0 * std::sqrt(drop.d_um / 100.0);
      const double swirl = 4.0;
      v = {speed * std::sin(half_angle) * std::cos(phi) - swirl * std::sin(phi), speed * std::cos(half_angle),
           speed * std::sin(half_angle) * std::sin(phi) + swirl * std::cos(phi)};
    } else {
      // A kerosene jet entering along +x at the burner wall (x = -8 mm, y = -6.5 mm) into an
      // air cross-flow along +y (Sect. 7.1): the plume bends downstream and widens; small
      // droplets follow the air (60 m/s), large ones lag.
      const double s = unit_double(rng);
      const double spread = 0.3 + 1.6 * s;
      p = {lo.x + 9.0 * (1.0 - std::exp(-3.0 * s)) + spread * normal(rng), lo.y + (hi.y - lo.y) * s + 0.5 * normal(rng),
           1.3 * spread * normal(rng)};
      const double lag = std::sqrt(drop.d_um / 100.0);
      v = {27.0 * std::exp(-3.0 * s) * (0.5 + lag), 60.0 - 25.0 * lag, 0.0};
    }
    if (!inside(p)) continue;
    const Vec3d half = v * (0.5 * dt_s * 1e3);  // m/s * s = m -> mm
    drop.a = p - half;
    drop.b = p + half;
    out.push_back(std::move(drop));
  }
  return out;
}

}  // namespace tomorig::sim
