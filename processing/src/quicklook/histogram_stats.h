#pragma once
// Figures from a full-resolution histogram of integer pixel values (bin v counts value v).
#include <cstdint>
#include <span>

namespace tomorig::quicklook::detail {

// The smallest value v whose cumulative count reaches fraction p of `total` (p in [0, 1]).
double quantile(std::span<const std::uint32_t> histogram, double total, double p);

// The value below which fraction p of the pixels lie, reading bin v as spread evenly over
// [v - 1/2, v + 1/2]: sub-count resolution for narrow distributions.
double quantile_continuous(std::span<const std::uint32_t> histogram, double total, double p);
// The fraction of pixels below `value` on the same reading.
double cumulative_continuous(std::span<const std::uint32_t> histogram, double value);

// Robust mode: the half-sample mode (Bickel & Fruehwirth 2006) on the histogram: repeatedly
// keep the narrowest run of bins holding half the remaining pixels, then take the mean of the
// last (at most 3) bins. A particle image adds to pixels, never subtracts, so the mode of a
// PIV frame is its background level unless particles cover almost every pixel.
double half_sample_mode(std::span<const std::uint32_t> histogram);

// Noise (1 sigma) of the background below `mode`: pixels without particles scatter
// symmetrically about the background, those with particles only lie above it, so the lower
// half is clean. For a normal distribution, a fraction 0.1587 / 0.5 of the pixels below the
// mode lie more than 1 sigma below it.
double lower_half_sigma(std::span<const std::uint32_t> histogram, double mode);

// The background level refined from a rough `mode` and `sigma` (bins): a Gaussian fitted to the
// histogram's lower flank, bins in [mode - 2 sigma, mode + sigma / 2] (log counts, weighted by
// the counts), whose centre is the level. Uses a few hundred bins' worth of pixels where the
// half-sample mode rests on a handful, and leaves out the upper flank, which particle light
// lifts. Returns `mode` if the fit is not a downward parabola or moves more than sigma.
double refine_mode(std::span<const std::uint32_t> histogram, double mode, double sigma);

// Noise of a background clipped at `floor` (a camera without black level: every negative
// excursion reads `floor`). Assumes the background is centred on the floor, which then holds
// Mb Phi(1/2 / sigma) of its Mb pixels; the value x reached by another half of the floor's count
// satisfies Phi(x / sigma) = 1.5 Phi(1/2 / sigma), solved for sigma. 0 if there is no solution
// (sigma too small for the floor to hold less than two thirds of the background).
double floor_clipped_sigma(std::span<const std::uint32_t> histogram, int floor);

}  // namespace tomorig::quicklook::detail
