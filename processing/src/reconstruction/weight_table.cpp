#include "weight_table.h"

#include <cmath>
#include <map>
#include <tuple>

#include <fmt/core.h>

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

bool is_rotated(const PsfSample& psf) {
  // A rotation by pi is the same ellipse; sigma_u == sigma_v is a circle at any angle.
  const double a = std::remainder(psf.angle_rad, 3.14159265358979323846);
  return std::fabs(a) > 1e-6 && std::fabs(psf.sigma_u_px - psf.sigma_v_px) > 1e-6;
}

double pixel_integrated_gaussian_2d(double du, double dv, const PsfSample& psf, int n) {
  const double c = std::cos(psf.angle_rad), s = std::sin(psf.angle_rad);
  const double iu = 1.0 / (2.0 * psf.sigma_u_px * psf.sigma_u_px), iv = 1.0 / (2.0 * psf.sigma_v_px * psf.sigma_v_px);
  const double norm = 1.0 / (2.0 * 3.14159265358979323846 * psf.sigma_u_px * psf.sigma_v_px * n * n);
  double sum = 0.0;
  for (int b = 0; b < n; ++b)
    for (int a = 0; a < n; ++a) {
      const double x = du - 0.5 + (a + 0.5) / n, y = dv - 0.5 + (b + 0.5) / n;
      const double r1 = c * x + s * y, r2 = -s * x + c * y;
      sum += std::exp(-r1 * r1 * iu - r2 * r2 * iv);
    }
  return sum * norm;
}

PatchWeights::PatchWeights(const std::vector<PsfSample>& psf_of_slice, int patch, int steps, int threads)
    : patch_(patch), steps_(steps) {
  // Levels: distinct (sigma_u, sigma_v) to 1e-2 px and angle to 1e-2 rad. Each costs
  // steps^2 * p^2 weights, so the key is coarser than the separable one.
  std::map<std::tuple<long, long, long>, int> level_of;
  std::vector<PsfSample> level_psf;
  for (const PsfSample& psf : psf_of_slice) {
    const auto key = std::make_tuple(std::lround(psf.sigma_u_px * 100.0), std::lround(psf.sigma_v_px * 100.0),
                                     std::lround(psf.angle_rad * 100.0));
    auto [it, inserted] = level_of.try_emplace(key, static_cast<int>(level_psf.size()));
    if (inserted) {
      PsfSample q;
      q.sigma_u_px = std::get<0>(key) / 100.0;
      q.sigma_v_px = std::get<1>(key) / 100.0;
      q.angle_rad = std::get<2>(key) / 100.0;
      level_psf.push_back(q);
    }
    slice_level_.push_back(static_cast<std::uint32_t>(it->second));
  }
  levels_ = static_cast<int>(level_psf.size());
  const std::size_t block = static_cast<std::size_t>(patch_) * patch_;
  const std::size_t rows = static_cast<std::size_t>(levels_) * steps_ * steps_;
  if (rows * block > (std::size_t{1} << 28))
    throw bad_input(fmt::format("reconstruction: the rotated PSF varies too finely with depth for the weight table "
                                "({} levels of {} x {} phases); use fewer lut_steps or a smoother PSF",
                                levels_, steps_, steps_));
  weights_.resize(rows * block);
  const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(rows);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t r = 0; r < count; ++r) {
    const int qu = static_cast<int>(r % steps_), qv = static_cast<int>((r / steps_) % steps_);
    const int level = static_cast<int>(r / (static_cast<std::ptrdiff_t>(steps_) * steps_));
    const double pu = static_cast<double>(qu) / steps_, pv = static_cast<double>(qv) / steps_;
    for (int b = 0; b < patch_; ++b)
      for (int a = 0; a < patch_; ++a) {
        // Same geometry as AxisWeights: pixel a of the patch is at a - phase - (p - 1) / 2 + 1/2.
        const double du = a - pu - 0.5 * (patch_ - 1) + 0.5, dv = b - pv - 0.5 * (patch_ - 1) + 0.5;
        weights_[static_cast<std::size_t>(r) * block + static_cast<std::size_t>(b) * patch_ + a] =
            static_cast<float>(pixel_integrated_gaussian_2d(du, dv, level_psf[static_cast<std::size_t>(level)]));
      }
  }
}

}  // namespace tomorig::recon::detail
