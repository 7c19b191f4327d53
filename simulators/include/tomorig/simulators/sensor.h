#pragma once
// The sensor: turns a float signal image (counts, noise-free) into the integer image a camera
// delivers: optional shot noise (Poisson on electrons) and read noise (Gaussian, electrons),
// a black level, rounding, and saturation at the full scale of the bit depth.
#include <cstdint>

#include "tomorig/core/image.h"

namespace tomorig::sim {

struct SensorOptions {
  int bit_depth = 16;              // 12 (Mono12, full scale 4095) or 16 (Mono16, 65535)
  bool noise = false;              // shot + read noise; false: the signal is only rounded
  double gain_counts_per_e = 1.0;  // counts per electron; shot noise variance = gain * signal
  double read_noise_e = 5.0;       // electrons, 1 sigma
  double offset_counts = 0.0;      // black level added before quantisation
  int threads = 0;                 // OpenMP threads; 0: the OpenMP default. Never changes results.

  // Throws tomorig::Error (bad_input) naming the field that is out of range.
  void validate() const;
  int full_scale() const { return (1 << bit_depth) - 1; }
};

// A u16 image of the same size as `signal` (an f32 image of counts). Noise draws come from
// per-row streams derived from `noise_seed`, so the result is the same on any thread count.
Image digitise(const Image& signal, const SensorOptions& options, std::uint64_t noise_seed);

}  // namespace tomorig::sim
