#include "tomorig/simulators/simulated_rig.h"

#include <cmath>
#include <exception>

#include <fmt/core.h>

#include "parallel.h"
#include "tomorig/core/error.h"
#include "tomorig/simulators/random.h"
#include "tomorig/simulators/scene.h"

namespace tomorig::sim {
namespace {

int bit_depth_of(const SimulatedCameraSpec& spec) {
  switch (spec.pixel_format) {
    case PixelFormat::Mono12: return 12;
    case PixelFormat::Mono16: return 16;
    default: break;
  }
  throw bad_input(fmt::format("simulated camera '{}': pixel format {} is not supported: use Mono12 or Mono16",
                              spec.id, to_string(spec.pixel_format)));
}

}  // namespace

void SimulationOptions::validate() const {
  // Written as !(a < x) so that NaN fails too.
  if (!(ppp > 0.0 && ppp <= 1.0))
    throw bad_input(fmt::format("simulation: ppp = {} is out of range: particle images per pixel must be in (0, 1]", ppp));
  if (!(peak_counts > 0) || !std::isfinite(peak_counts))
    throw bad_input(fmt::format("simulation: peak_counts = {} must be > 0", peak_counts));
  if (!(read_noise_e >= 0) || !std::isfinite(read_noise_e))
    throw bad_input(fmt::format("simulation: read_noise_e = {} must be >= 0", read_noise_e));
  if (!(gain_counts_per_e > 0) || !std::isfinite(gain_counts_per_e))
    throw bad_input(fmt::format("simulation: gain_counts_per_e = {} must be > 0", gain_counts_per_e));
  if (!(rate_hz > 0) || !std::isfinite(rate_hz))
    throw bad_input(fmt::format("simulation: rate_hz = {} must be > 0", rate_hz));
  if (dt_ns < 0) throw bad_input(fmt::format("simulation: dt_ns = {} must be >= 0", dt_ns));
  if (threads < 0) throw bad_input(fmt::format("simulation: threads = {} must be >= 0", threads));
  for (std::size_t i = 0; i < cameras.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (cameras[i].id == cameras[j].id)
        throw bad_input(fmt::format("simulation: camera id '{}' is used twice", cameras[i].id));
}

std::size_t particle_count(double ppp, const std::vector<SimulatedCameraSpec>& cameras) {
  if (cameras.empty()) return 0;
  double pixels = 0;
  for (const auto& c : cameras) pixels += static_cast<double>(c.width) * c.height;
  return static_cast<std::size_t>(std::llround(ppp * pixels / static_cast<double>(cameras.size())));
}

SimulatedRig::SimulatedRig(const SimulationOptions& options)
    : options_(options), case_(&find_case(options.case_name)) {
  options_.validate();
  const std::vector<SimulatedCameraSpec>& specs = options_.cameras.empty() ? case_->cameras : options_.cameras;
  if (specs.empty()) throw bad_input("simulation: the rig has no cameras to render");
  for (const SimulatedCameraSpec& spec : specs) {
    bit_depth_of(spec);  // refuses unsupported formats before any rendering
    cameras_.push_back({spec, calibration::PinholeCamera::yawed(spec.yaw_deg, spec.focal_length_mm, spec.pixel_pitch_um,
                                                                spec.distance_mm, spec.width, spec.height)});
  }
  flow_ = case_->make_flow(*case_);
  sheet_ = LightSheet::for_slab(options_.light_sheet, case_->slab);
  image_options_.sigma_px = case_->sigma_px;
  image_options_.peak_counts = options_.peak_counts;
  image_options_.threads = options_.threads;
  image_options_.validate();
  particles_per_set_ = particle_count(options_.ppp, specs);
}

std::vector<Vec3d> SimulatedRig::particle_midpoints(std::uint64_t set_index) const {
  return uniform_particles(case_->slab, particles_per_set_, derive_seed(options_.seed, {kParticleStream, set_index}));
}

Image SimulatedRig::render_signal(std::size_t camera, std::span<const Vec3d> particles) const {
  const SimulatedCamera& cam = cameras_.at(camera);
  Image signal = Image::allocate(cam.spec.width, cam.spec.height, SampleType::f32);
  render_particles(cam.model, particles, sheet_, image_options_, signal);
  return signal;
}

SimulatedSet SimulatedRig::render_set(std::uint64_t set_index) const {
  return render_set(set_index, options_.dt_ns);
}

SimulatedSet SimulatedRig::render_set(std::uint64_t set_index, std::int64_t dt_ns) const {
  if (dt_ns < 0) throw bad_input(fmt::format("simulation: set {}: dt_ns = {} must be >= 0", set_index, dt_ns));
  if (options_.dt_ns == 0 && dt_ns != 0)
    throw bad_input(fmt::format("simulation: set {}: dt_ns = {} cannot be rendered: the flow's time base "
                                "(options dt_ns) is 0",
                                set_index, dt_ns));
  SimulatedSet out;
  const std::vector<Vec3d> midpoints = particle_midpoints(set_index);
  ParticlePair pair;
  if (dt_ns == options_.dt_ns) {
    pair = straddle(midpoints, *flow_);
  } else {
    // A steady flow: the displacement grows linearly with the pulse separation. Central
    // straddling keeps the mid-time positions; only the half-displacements scale.
    const double half_scale = 0.5 * static_cast<double>(dt_ns) / static_cast<double>(options_.dt_ns);
    pair.a.resize(midpoints.size());
    pair.b.resize(midpoints.size());
    for (std::size_t n = 0; n < midpoints.size(); ++n) {
      const Vec3d half = flow_->displacement(midpoints[n]) * half_scale;
      pair.a[n] = midpoints[n] - half;
      pair.b[n] = midpoints[n] + half;
    }
  }

  FrameSet& frames = out.frames;
  frames.set_index = set_index;
  frames.trigger_index = set_index;
  frames.trigger_timestamp_ns = std::llround(static_cast<double>(set_index) * 1e9 / options_.rate_hz);
  frames.dt_ns = dt_ns;
  frames.cameras.resize(cameras_.size());

  // One job per (camera, exposure): 8 independent images for tpiv-thesis. Parallel over
  // images rather than inside each: fewer, larger tasks, and the images do not depend on how
  // jobs are spread over threads. The kernels inside run on one thread each.
  const int jobs = static_cast<int>(2 * cameras_.size());
  ParticleImageOptions image_options = image_options_;
  image_options.threads = 1;
  std::vector<std::exception_ptr> errors(jobs);
#pragma omp parallel for num_threads(detail::thread_count(options_.threads)) schedule(dynamic, 1)
  for (int job = 0; job < jobs; ++job) {
    // An exception must not leave an OpenMP region: keep it and rethrow after the loop.
    try {
      const std::size_t c = static_cast<std::size_t>(job / 2);
      const Exposure e = job % 2 == 0 ? Exposure::A : Exposure::B;
      const SimulatedCamera& cam = cameras_[c];
      Image signal = Image::allocate(cam.spec.width, cam.spec.height, SampleType::f32);
      render_particles(cam.model, e == Exposure::A ? pair.a : pair.b, sheet_, image_options, signal);
      SensorOptions sensor;
      sensor.bit_depth = bit_depth_of(cam.spec);
      sensor.noise = options_.noise;
      sensor.read_noise_e = options_.read_noise_e;
      sensor.gain_counts_per_e = options_.gain_counts_per_e;
      sensor.threads = 1;
      const std::uint64_t noise_seed =
          derive_seed(options_.seed, {kNoiseStream, set_index, c, static_cast<std::uint64_t>(e)});
      Frame& frame = frames.cameras[c][e];
      frame.image = digitise(signal, sensor, noise_seed);
      frame.timestamp_ns = frames.trigger_timestamp_ns + (e == Exposure::A ? 0 : dt_ns);
    } catch (...) {
      errors[job] = std::current_exception();
    }
  }
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
  for (std::size_t c = 0; c < cameras_.size(); ++c) frames.cameras[c].camera_id = cameras_[c].spec.id;

  out.particles_a = std::move(pair.a);
  out.particles_b = std::move(pair.b);
  return out;
}

}  // namespace tomorig::sim
