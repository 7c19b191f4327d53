#include "weight_table.h"

#include <cmath>
#include <map>

#include "tomorig/core/error.h"

namespace tomorig::recon::detail {

double pixel_integrated_gaussian(double d, double sigma) {
  const double k = 1.0 / (std::sqrt(2.0) * sigma);
  return 0.5 * (std::erf((d + 0.5) * k) - std::erf((d - 0.5) * k));
}

AxisWeights::AxisWeights(const std::vector<double>& sigma_of_slice, int patch, int steps)
    : patch_(patch), steps_(steps) {
  // Distinct sigmas to 1e-3 px: a constant PSF has one level, a depth-varying one a few.
  std::map<long, int> level_of;
  std::vector<double> level_sigma;
  slice_level_.reserve(sigma_of_slice.size());
  for (double sigma : sigma_of_slice) {
    const long key = std::lround(sigma * 1000.0);
    auto [it, inserted] = level_of.try_emplace(key, static_cast<int>(level_sigma.size()));
    if (inserted) level_sigma.push_back(static_cast<double>(key) / 1000.0);
    slice_level_.push_back(static_cast<std::uint16_t>(it->second));
  }
  levels_ = static_cast<int>(level_sigma.size());
  if (static_cast<long>(levels_) * steps_ > 65535)
    throw bad_input("reconstruction: the PSF varies too finely with depth for the weight table (more than 65535 "
                    "rows); use fewer lut_steps or a smoother sigma(z)");
  weights_.resize(static_cast<std::size_t>(levels_) * steps_ * patch_);
  for (int l = 0; l < levels_; ++l)
    for (int q = 0; q < steps_; ++q)
      for (int a = 0; a < patch_; ++a) {
        const double phase = static_cast<double>(q) / steps_;
        const double d = a - phase - 0.5 * (patch_ - 1) + 0.5;
        weights_[(static_cast<std::size_t>(l) * steps_ + q) * patch_ + a] =
            static_cast<float>(pixel_integrated_gaussian(d, level_sigma[l]));
      }
}

}  // namespace tomorig::recon::detail
