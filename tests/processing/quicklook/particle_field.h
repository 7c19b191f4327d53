#pragma once
// Particle image fields rendered by the simulator library (particle_renderer.h, sensor.h) with
// a known truth: particle count, particle image sigma, background, noise.
#include <cstdint>
#include <random>
#include <vector>

#include "tomorig/simulators/particle_renderer.h"
#include "tomorig/simulators/random.h"
#include "tomorig/simulators/sensor.h"

namespace tomorig::quicklook::testing {

struct FieldSpec {
  int width = 512, height = 512;
  double ppp = 0.05;        // particles whose centres lie on the image, per pixel
  double sigma_px = 0.75;   // d_tau = 4 sigma
  double peak_counts = 1000.0;
  double offset_counts = 100.0;  // black level
  bool noise = true;             // shot noise (gain 1) + read noise
  double read_noise_e = 5.0;
  int bit_depth = 16;
  std::uint64_t seed = 1;
};

struct Field {
  std::vector<sim::ParticleImage> particles;
  Image signal;  // noise-free counts, f32, without the black level
  Image image;   // u16, as a camera delivers it
  double true_ppp() const { return static_cast<double>(particles.size()) / (static_cast<double>(signal.width()) * signal.height()); }
};

// Centres uniform over the image area [-0.5, W - 0.5] x [-0.5, H - 0.5].
inline std::vector<sim::ParticleImage> random_particles(const FieldSpec& spec) {
  std::mt19937_64 rng(sim::derive_seed(spec.seed, {sim::kParticleStream}));
  const auto count = static_cast<std::size_t>(std::llround(spec.ppp * spec.width * spec.height));
  std::vector<sim::ParticleImage> out(count);
  for (auto& p : out) {
    p.centre = {sim::unit_double(rng) * spec.width - 0.5, sim::unit_double(rng) * spec.height - 0.5};
    p.peak = spec.peak_counts;
  }
  return out;
}

inline Image digitise(const Image& signal, const FieldSpec& spec, std::uint64_t noise_seed) {
  sim::SensorOptions sensor;
  sensor.bit_depth = spec.bit_depth;
  sensor.noise = spec.noise;
  sensor.read_noise_e = spec.read_noise_e;
  sensor.offset_counts = spec.offset_counts;
  sensor.threads = 1;
  return sim::digitise(signal, sensor, noise_seed);
}

inline Image render(const std::vector<sim::ParticleImage>& particles, const FieldSpec& spec) {
  sim::ParticleImageOptions options;
  options.sigma_px = spec.sigma_px;
  options.peak_counts = spec.peak_counts;
  options.threads = 1;
  Image signal = Image::allocate(spec.width, spec.height, SampleType::f32);
  sim::render_particle_images(particles, options, signal);
  return signal;
}

inline Field make_field(const FieldSpec& spec) {
  Field f;
  f.particles = random_particles(spec);
  f.signal = render(f.particles, spec);
  f.image = digitise(f.signal, spec, sim::derive_seed(spec.seed, {sim::kNoiseStream}));
  return f;
}

}  // namespace tomorig::quicklook::testing
