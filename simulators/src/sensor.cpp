#include "tomorig/simulators/sensor.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/core.h>

#include "parallel.h"
#include "tomorig/core/error.h"
#include "tomorig/simulators/random.h"

namespace tomorig::sim {

void SensorOptions::validate() const {
  if (bit_depth != 12 && bit_depth != 16)
    throw bad_input(fmt::format("sensor: bit_depth = {} is not supported: use 12 or 16", bit_depth));
  if (!(gain_counts_per_e > 0) || !std::isfinite(gain_counts_per_e))
    throw bad_input(fmt::format("sensor: gain_counts_per_e = {} must be > 0", gain_counts_per_e));
  if (!(read_noise_e >= 0) || !std::isfinite(read_noise_e))
    throw bad_input(fmt::format("sensor: read_noise_e = {} must be >= 0", read_noise_e));
  if (!(offset_counts >= 0) || !std::isfinite(offset_counts))
    throw bad_input(fmt::format("sensor: offset_counts = {} must be >= 0", offset_counts));
  if (threads < 0) throw bad_input(fmt::format("sensor: threads = {} must be >= 0", threads));
}

Image digitise(const Image& signal, const SensorOptions& options, std::uint64_t noise_seed) {
  options.validate();
  if (signal.empty() || signal.type() != SampleType::f32)
    throw runtime_error("digitise: the signal image must be an allocated f32 image");
  const int width = signal.width(), height = signal.height();
  Image out = Image::allocate(width, height, SampleType::u16);
  const double full_scale = options.full_scale();
  const double gain = options.gain_counts_per_e;

#pragma omp parallel for num_threads(detail::thread_count(options.threads)) schedule(static)
  for (int y = 0; y < height; ++y) {
    const float* in = signal.row<float>(y);
    std::uint16_t* o = out.row<std::uint16_t>(y);
    // One stream per row: the draws of a row do not depend on which thread renders it.
    std::mt19937_64 engine(derive_seed(noise_seed, {static_cast<std::uint64_t>(y)}));
    std::normal_distribution<double> read(0.0, options.read_noise_e);
    for (int x = 0; x < width; ++x) {
      double counts = std::max(0.0, static_cast<double>(in[x]));
      if (options.noise) {
        const double mean_e = counts / gain;
        double electrons = 0.0;
        if (mean_e > 0) electrons = static_cast<double>(std::poisson_distribution<long long>(mean_e)(engine));
        if (options.read_noise_e > 0) electrons += read(engine);
        counts = electrons * gain;
      }
      counts = std::clamp(std::nearbyint(counts + options.offset_counts), 0.0, full_scale);
      o[x] = static_cast<std::uint16_t>(counts);
    }
  }
  return out;
}

}  // namespace tomorig::sim
