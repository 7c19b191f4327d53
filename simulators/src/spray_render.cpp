// spray-thesis rendering: droplet shadows (disc x Gaussian PSF, integrated over pixels), the
// LED bright field and the sensor (spray.h).
#include <algorithm>
#include <cmath>
#include <exception>
#include <random>
#include <vector>

#include <fmt/core.h>

#include "parallel.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"
#include "tomorig/simulators/random.h"
#include "tomorig/simulators/sensor.h"
#include "tomorig/simulators/spray.h"

namespace tomorig::sim {
namespace {

constexpr std::uint64_t kSprayNoiseStream = 0x73707261796eULL;  // "sprayn"
constexpr std::uint64_t kPulseStream = 0x70756c7365ULL;         // "pulse"
constexpr std::uint64_t kBrightStream = 0x627269676874ULL;      // "bright"

// One droplet's shadow depletion D (0..1, the fraction of the disc's light removed before the
// transmission factor) on a window of pixels, pixel-integrated. The disc is sampled by points
// on rings no further apart than half the optics' sigma; each point adds a pixel-integrated
// Gaussian (erf differences: exact over the pixel's area). An independent route to the same
// model Eq. 6.4 states in closed form.
struct Patch {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  std::vector<double> depletion;  // w * h, row-major
};

Patch shadow_patch(double u, double v, double radius_px, double sigma_px, int width, int height) {
  Patch p;
  const double reach = radius_px + 5.0 * sigma_px + 1.0;
  p.x0 = std::max(0, static_cast<int>(std::floor(u - reach)));
  p.y0 = std::max(0, static_cast<int>(std::floor(v - reach)));
  const int x1 = std::min(width - 1, static_cast<int>(std::ceil(u + reach)));
  const int y1 = std::min(height - 1, static_cast<int>(std::ceil(v + reach)));
  if (x1 < p.x0 || y1 < p.y0) return p;
  p.w = x1 - p.x0 + 1;
  p.h = y1 - p.y0 + 1;
  p.depletion.assign(static_cast<std::size_t>(p.w) * p.h, 0.0);
  const double spacing = 0.5 * sigma_px;
  const int rings = std::max(1, static_cast<int>(std::ceil(radius_px / spacing)));
  const double dr = radius_px / rings;
  const double k = 1.0 / (std::sqrt(2.0) * sigma_px);
  std::vector<double> gx(static_cast<std::size_t>(p.w)), gy(static_cast<std::size_t>(p.h));
  for (int j = 0; j < rings; ++j) {
    const double r = (j + 0.5) * dr;
    const double area = M_PI * dr * dr * ((j + 1) * (j + 1) - j * j);  // pixels^2
    const int n = rings == 1 ? 1 : std::max(3, static_cast<int>(std::ceil(2.0 * M_PI * r / spacing)));
    const double weight = area / n;
    for (int q = 0; q < n; ++q) {
      const double phi = 2.0 * M_PI * (q + 0.5 * (j % 2)) / n;
      const double cx = n == 1 ? u : u + r * std::cos(phi), cy = n == 1 ? v : v + r * std::sin(phi);
      for (int i = 0; i < p.w; ++i) {
        const double x = p.x0 + i;
        gx[i] = 0.5 * (std::erf((x + 0.5 - cx) * k) - std::erf((x - 0.5 - cx) * k));
      }
      for (int i = 0; i < p.h; ++i) {
        const double y = p.y0 + i;
        gy[i] = 0.5 * (std::erf((y + 0.5 - cy) * k) - std::erf((y - 0.5 - cy) * k));
      }
      for (int yy = 0; yy < p.h; ++yy) {
        const double wy = weight * gy[yy];
        double* row = &p.depletion[static_cast<std::size_t>(yy) * p.w];
        for (int xx = 0; xx < p.w; ++xx) row[xx] += wy * gx[xx];
      }
    }
  }
  return p;
}

struct Projected {
  bool in_view = false;
  double u = 0, v = 0, radius_px = 0, sigma_px = 0;
};

Projected project(const SprayCamera& cam, const Vec3d& p, double d_um) {
  Projected out;
  const Vec2d uv = cam.pinhole.project(p);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return out;
  out.u = uv.x;
  out.v = uv.y;
  const double object_pixel_um = cam.pixel_pitch_um / cam.pinhole.magnification(p, cam.pixel_pitch_um);
  out.radius_px = 0.5 * d_um / object_pixel_um;
  const double chi_px = spray_chi_um(cam, p.z) / object_pixel_um;
  // chi is the whole system's (Eq. 6.1: sigma = chi / 2); the pixel box adds 1/12 px^2.
  out.sigma_px = std::sqrt(std::max(0.25 * chi_px * chi_px - 1.0 / 12.0, 1e-4));
  out.in_view = uv.x >= -0.5 && uv.y >= -0.5 && uv.x <= cam.width - 0.5 && uv.y <= cam.height - 0.5;
  return out;
}

std::vector<optics::TransmissionTable> transmission_tables(const SprayCase& c) {
  const optics::TransmissionModel model(c.optics.liquid, c.optics.spectrum);
  std::vector<optics::TransmissionTable> out;
  for (const SprayCamera& cam : c.cameras)
    out.emplace_back(model, optics::object_numerical_aperture(cam.f_number, cam.magnification), c.options.d_max_um);
  return out;
}

double bright_field(const SprayCamera& cam, double level, double vignetting, int x, int y) {
  const double cx = 0.5 * (cam.width - 1), cy = 0.5 * (cam.height - 1);
  const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (cx * cx + cy * cy);
  return level * (1.0 - vignetting * r2);
}

Image digitise_camera(const SprayCase& c, std::size_t camera, const Image& signal, std::uint64_t seed) {
  SensorOptions sensor;
  sensor.bit_depth = 16;
  sensor.noise = c.options.noise;
  sensor.gain_counts_per_e = c.cameras[camera].gain_counts_per_e;
  sensor.read_noise_e = 1.5;
  sensor.threads = 1;
  return digitise(signal, sensor, seed);
}

double pulse_energy(const SprayCase& c, std::uint64_t stream, std::uint64_t index, std::size_t camera, int exposure) {
  std::mt19937_64 rng(derive_seed(c.options.seed, {stream, index, camera, static_cast<std::uint64_t>(exposure)}));
  const double u1 = std::max(unit_double(rng), 1e-300), u2 = unit_double(rng);
  return 1.0 + c.options.pulse_jitter * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace

SpraySet render_spray_set(const SprayCase& c, std::uint64_t set_index) {
  return render_spray_set(c, set_index, std::llround(c.options.dt_us * 1e3));
}

SpraySet render_spray_set(const SprayCase& c, std::uint64_t set_index, std::int64_t dt_ns) {
  if (dt_ns < 0) throw bad_input(fmt::format("spray: set {}: dt_ns = {} must be >= 0", set_index, dt_ns));
  const std::int64_t nominal_ns = std::llround(c.options.dt_us * 1e3);
  if (nominal_ns == 0 && dt_ns != 0)
    throw bad_input(fmt::format("spray: set {}: dt_ns = {} cannot be rendered: the case's dt_us is 0", set_index, dt_ns));
  SpraySet out;
  out.droplets = spray_droplets(c, set_index);
  if (dt_ns != nominal_ns) {
    // Steady droplet motion over the pulse separation: only the half-displacements scale.
    const double scale = static_cast<double>(dt_ns) / static_cast<double>(nominal_ns);
    for (Droplet& d : out.droplets) {
      const Vec3d mid = (d.a + d.b) * 0.5, half = (d.b - d.a) * (0.5 * scale);
      d.a = mid - half;
      d.b = mid + half;
    }
  }
  const std::vector<optics::TransmissionTable> tables = transmission_tables(c);
  const std::size_t ncam = c.cameras.size();
  for (Droplet& d : out.droplets) {
    d.min_intensity.assign(ncam, 1.0);
    d.visible.assign(ncam, false);
  }
  const double level = c.options.bright_fraction * 65535.0;
  out.frames.set_index = set_index;
  out.frames.trigger_index = set_index;
  out.frames.dt_ns = dt_ns;
  out.frames.cameras.resize(ncam);
  out.pulse_energy_a.resize(ncam);
  out.pulse_energy_b.resize(ncam);
  const int jobs = static_cast<int>(2 * ncam);
  std::vector<std::exception_ptr> errors(jobs);
  // Exposure A's deepest shadow per camera and droplet (1: out of view): each job writes only
  // its own camera's row, and the droplets are filled in after the loop.
  std::vector<std::vector<double>> deepest_a(ncam, std::vector<double>(out.droplets.size(), 1.0));
#pragma omp parallel for num_threads(detail::thread_count(c.options.threads)) schedule(dynamic, 1)
  for (int job = 0; job < jobs; ++job) {
    try {
      const std::size_t ci = static_cast<std::size_t>(job / 2);
      const int e = job % 2;
      const SprayCamera& cam = c.cameras[ci];
      // Transmission of all shadows, multiplied (each droplet removes its share of what is left).
      std::vector<float> transmission(static_cast<std::size_t>(cam.width) * cam.height, 1.0f);
      for (std::size_t di = 0; di < out.droplets.size(); ++di) {
        const Droplet& drop = out.droplets[di];
        const Projected pr = project(cam, e == 0 ? drop.a : drop.b, drop.d_um);
        if (!std::isfinite(pr.u)) continue;
        const Patch patch = shadow_patch(pr.u, pr.v, pr.radius_px, pr.sigma_px, cam.width, cam.height);
        if (patch.w == 0) continue;
        const double opacity = 1.0 - tables[ci].tau(drop.d_um);
        double deepest = 1.0;
        for (int yy = 0; yy < patch.h; ++yy)
          for (int xx = 0; xx < patch.w; ++xx) {
            const double t = 1.0 - opacity * patch.depletion[static_cast<std::size_t>(yy) * patch.w + xx];
            deepest = std::min(deepest, t);
            transmission[static_cast<std::size_t>(patch.y0 + yy) * cam.width + patch.x0 + xx] *= static_cast<float>(t);
          }
        if (e == 0 && pr.in_view) deepest_a[ci][di] = deepest;
      }
      const double energy = pulse_energy(c, kPulseStream, set_index, ci, e) * (e == 0 ? 1.0 : c.options.pulse_b_energy);
      (e == 0 ? out.pulse_energy_a : out.pulse_energy_b)[ci] = energy;
      Image signal = Image::allocate(cam.width, cam.height, SampleType::f32);
      for (int y = 0; y < cam.height; ++y) {
        float* row = signal.row<float>(y);
        for (int x = 0; x < cam.width; ++x)
          row[x] = static_cast<float>(energy * bright_field(cam, level, c.options.vignetting, x, y) *
                                      transmission[static_cast<std::size_t>(y) * cam.width + x]);
      }
      Frame& frame = out.frames.cameras[ci][e == 0 ? Exposure::A : Exposure::B];
      frame.image = digitise_camera(c, ci, signal, derive_seed(c.options.seed, {kSprayNoiseStream, set_index, ci,
                                                                                 static_cast<std::uint64_t>(e)}));
      frame.timestamp_ns = e == 0 ? 0 : out.frames.dt_ns;
    } catch (...) {
      errors[job] = std::current_exception();
    }
  }
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
  for (std::size_t ci = 0; ci < ncam; ++ci) {
    out.frames.cameras[ci].camera_id = c.cameras[ci].id;
    for (std::size_t di = 0; di < out.droplets.size(); ++di) {
      out.droplets[di].min_intensity[ci] = deepest_a[ci][di];
      out.droplets[di].visible[ci] = deepest_a[ci][di] <= c.cameras[ci].threshold_value();
    }
  }
  return out;
}

Image render_bright_field(const SprayCase& c, std::size_t camera, std::uint64_t frame) {
  const SprayCamera& cam = c.cameras.at(camera);
  const double level = c.options.bright_fraction * 65535.0;
  const double energy = pulse_energy(c, kBrightStream, frame, camera, 0);
  Image signal = Image::allocate(cam.width, cam.height, SampleType::f32);
  for (int y = 0; y < cam.height; ++y) {
    float* row = signal.row<float>(y);
    for (int x = 0; x < cam.width; ++x) row[x] = static_cast<float>(energy * bright_field(cam, level, c.options.vignetting, x, y));
  }
  return digitise_camera(c, camera, signal, derive_seed(c.options.seed, {kBrightStream, frame, camera, 7}));
}

Image render_spray_edge_target(const SprayCase& c, std::size_t camera, double z_mm, std::uint64_t frame,
                               double slant_deg) {
  const SprayCamera& cam = c.cameras.at(camera);
  const double level = c.options.bright_fraction * 65535.0;
  const double energy = pulse_energy(c, kBrightStream, frame + 1000003, camera, 1);
  constexpr double kChromium = 0.05;
  const double cs = std::cos(slant_deg * M_PI / 180.0), sn = std::sin(slant_deg * M_PI / 180.0);
  // The PSF lives in the image: the same sigma in pixels as a droplet at this depth gets
  // (project() in render_spray_set), the pixel box added by sub-sampling below.
  const Vec3d centre{0.0, 0.0, z_mm};
  const double object_pixel_um = cam.pixel_pitch_um / cam.pinhole.magnification(centre, cam.pixel_pitch_um);
  const double chi_px = spray_chi_um(cam, z_mm) / object_pixel_um;
  const double sigma_px = std::sqrt(std::max(0.25 * chi_px * chi_px - 1.0 / 12.0, 1e-4));
  const double k = 1.0 / (std::sqrt(2.0) * sigma_px);
  // The bars cover a band of the mask 30 % of the image high (the rest is clear glass): enough
  // rows for every edge, at a third of the rendering time.
  const int band0 = static_cast<int>(0.35 * cam.height), band1 = static_cast<int>(0.65 * cam.height);
  // s = the plane coordinate across the bars (mm) at every pixel centre of the band.
  const int w = cam.width;
  std::vector<double> across(static_cast<std::size_t>(w) * (band1 - band0 + 2));
  for (int y = band0; y <= band1 + 1; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec3d p = cam.pinhole.back_project({double(x), double(y)}, z_mm);
      across[static_cast<std::size_t>(y - band0) * w + x] = p.x * cs - p.y * sn;
    }
  Image signal = Image::allocate(cam.width, cam.height, SampleType::f32);
  constexpr int kSub = 4;  // 4 x 4 samples over each pixel's area
#pragma omp parallel for num_threads(detail::thread_count(c.options.threads)) schedule(static)
  for (int y = 0; y < cam.height; ++y) {
    float* row = signal.row<float>(y);
    for (int x = 0; x < w; ++x) {
      double mask = 1.0;
      if (y >= band0 && y <= band1 && x + 1 < w) {
        // s is linear over a pixel; its gradient (mm per pixel) converts plane distances to pixels.
        const double s0 = across[static_cast<std::size_t>(y - band0) * w + x];
        const double du = across[static_cast<std::size_t>(y - band0) * w + x + 1] - s0;
        const double dv = across[static_cast<std::size_t>(y + 1 - band0) * w + x] - s0;
        const double mm_per_px = std::hypot(du, dv);
        double sum = 0.0;
        for (int j = 0; j < kSub; ++j)
          for (int i = 0; i < kSub; ++i) {
            const double s = s0 + ((i + 0.5) / kSub - 0.5) * du + ((j + 0.5) / kSub - 0.5) * dv;
            // Light on [0, 1) mm of each 2 mm period; the bars are far wider than the blur, so
            // only the nearest edge counts: Phi(signed distance in pixels / sigma).
            const double q = s - 2.0 * std::floor(s / 2.0);
            const double d_mm = q < 1.0 ? std::min(q, 1.0 - q) : -std::min(q - 1.0, 2.0 - q);
            sum += 0.5 * (1.0 + std::erf(d_mm / mm_per_px * k));
          }
        mask = kChromium + (1.0 - kChromium) * sum / (kSub * kSub);
      }
      row[x] = static_cast<float>(energy * bright_field(cam, level, c.options.vignetting, x, y) * mask);
    }
  }
  return digitise_camera(c, camera, signal, derive_seed(c.options.seed, {kBrightStream, frame, camera, 11}));
}

Image render_spray_chessboard_target(const SprayCase& c, std::size_t camera, double z_mm, std::uint64_t frame,
                                     double square_mm, double rotation_deg) {
  if (!(square_mm > 0) || !(std::abs(rotation_deg) < 45))
    throw bad_input(fmt::format("spray chessboard: square {} mm must be > 0 and the turn {} deg within +-45", square_mm,
                                rotation_deg));
  const SprayCamera& cam = c.cameras.at(camera);
  const double level = c.options.bright_fraction * 65535.0;
  const double energy = pulse_energy(c, kBrightStream, frame + 2000003, camera, 1);
  constexpr double kChromium = 0.05;
  const double cs = std::cos(rotation_deg * M_PI / 180.0), sn = std::sin(rotation_deg * M_PI / 180.0);
  // The image-space PSF at this depth, as a droplet there gets it (project() above).
  const Vec3d centre{0.0, 0.0, z_mm};
  const double object_pixel_um = cam.pixel_pitch_um / cam.pinhole.magnification(centre, cam.pixel_pitch_um);
  const double chi_px = spray_chi_um(cam, z_mm) / object_pixel_um;
  const double sigma_px = std::sqrt(std::max(0.25 * chi_px * chi_px - 1.0 / 12.0, 1e-4));
  const double k = 1.0 / (std::sqrt(2.0) * sigma_px);
  const int w = cam.width, h = cam.height;
  // Board coordinates (s, t) in mm at every pixel centre (one extra row and column for the
  // gradients); NaN where the line of sight misses the plane.
  std::vector<double> s_at(static_cast<std::size_t>(w + 1) * (h + 1)), t_at(s_at.size());
  for (int y = 0; y <= h; ++y)
    for (int x = 0; x <= w; ++x) {
      const Vec3d p = cam.pinhole.back_project({double(x), double(y)}, z_mm);
      const std::size_t i = static_cast<std::size_t>(y) * (w + 1) + x;
      s_at[i] = p.x * cs + p.y * sn;
      t_at[i] = -p.x * sn + p.y * cs;
    }
  // Signed distance (mm) to the nearest line of a square wave of period 2 * square: > 0 inside
  // the squares counted as +1.
  const auto signed_distance = [square_mm](double s) {
    const double period = 2.0 * square_mm;
    const double q = s - period * std::floor(s / period);
    return q < square_mm ? std::min(q, square_mm - q) : -std::min(q - square_mm, period - q);
  };
  Image signal = Image::allocate(w, h, SampleType::f32);
  constexpr int kSub = 4;  // 4 x 4 samples over each pixel's area
#pragma omp parallel for num_threads(detail::thread_count(c.options.threads)) schedule(static)
  for (int y = 0; y < h; ++y) {
    float* row = signal.row<float>(y);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * (w + 1) + x;
      const double s0 = s_at[i], t0 = t_at[i];
      double mask = 1.0;
      if (std::isfinite(s0) && std::isfinite(t0)) {
        // s and t are linear over a pixel; their gradients (mm per pixel) turn plane distances
        // into image pixels, where the PSF lives.
        const double su = s_at[i + 1] - s0, sv = s_at[i + w + 1] - s0;
        const double tu = t_at[i + 1] - t0, tv = t_at[i + w + 1] - t0;
        const double s_mm_per_px = std::hypot(su, sv), t_mm_per_px = std::hypot(tu, tv);
        // Far from every line (the pixel's reach plus 6 sigma: erf = 1 to 1e-8) the board is
        // its plain colour; only the pixels near a line need the blurred sub-samples.
        const double ds = signed_distance(s0), dt = signed_distance(t0);
        const double reach_s = 0.5 * (std::abs(su) + std::abs(sv)) + 6.0 * sigma_px * s_mm_per_px;
        const double reach_t = 0.5 * (std::abs(tu) + std::abs(tv)) + 6.0 * sigma_px * t_mm_per_px;
        if (std::abs(ds) > reach_s && std::abs(dt) > reach_t) {
          mask = (ds > 0) == (dt > 0) ? 1.0 : kChromium;
          row[x] = static_cast<float>(energy * bright_field(cam, level, c.options.vignetting, x, y) * mask);
          continue;
        }
        double sum = 0.0;
        for (int j = 0; j < kSub; ++j)
          for (int q = 0; q < kSub; ++q) {
            const double fu = (q + 0.5) / kSub - 0.5, fv = (j + 0.5) / kSub - 0.5;
            const double s = s0 + fu * su + fv * sv, t = t0 + fu * tu + fv * tv;
            // Each board line blurred on its own ((2 Phi - 1) of the distance in pixels / sigma),
            // the board their product (exact away from the corners); 1 on the clear squares.
            const double bs = std::erf(signed_distance(s) / s_mm_per_px * k);
            const double bt = std::erf(signed_distance(t) / t_mm_per_px * k);
            sum += 0.5 * (1.0 + bs * bt);
          }
        mask = kChromium + (1.0 - kChromium) * sum / (kSub * kSub);
      }
      row[x] = static_cast<float>(energy * bright_field(cam, level, c.options.vignetting, x, y) * mask);
    }
  }
  return digitise_camera(c, camera, signal, derive_seed(c.options.seed, {kBrightStream, frame, camera, 13}));
}

}  // namespace tomorig::sim
