#include "tomorig/processing/optics/droplet_size.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"
#include "tomorig/processing/optics/transmission.h"

namespace tomorig::optics {
namespace {

constexpr double kStepUm = 0.5;  // the table's diameter step: finer than any size class edge

double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front() * (x.front() > 0 ? at / x.front() : 0.0);
  if (at >= x.back()) return y.back();
  const auto it = std::upper_bound(x.begin(), x.end(), at);
  const std::size_t k = static_cast<std::size_t>(it - x.begin());
  const double t = (at - x[k - 1]) / (x[k] - x[k - 1]);
  return y[k - 1] + t * (y[k] - y[k - 1]);
}

}  // namespace

DropletSizeModel::DropletSizeModel(const VisibilitySetup& setup, const std::vector<double>& object_pixel_um) {
  if (object_pixel_um.size() != setup.cameras.size() || setup.cameras.empty())
    throw bad_input(fmt::format("droplet size model: {} object pixels for {} cameras", object_pixel_um.size(),
                                setup.cameras.size()));
  for (const double p : object_pixel_um)
    if (!(p > 0)) throw bad_input("droplet size model: an object pixel must be > 0 um");
  const TransmissionModel model(setup.liquid, setup.spectrum);
  std::vector<TransmissionTable> tables;
  for (const CameraOptics& c : setup.cameras)
    tables.emplace_back(model, object_numerical_aperture(c.f_number, c.magnification), setup.d_max_um);
  for (double d = kStepUm; d <= setup.d_max_um + 1e-9; d += kStepUm) {
    double removed = 0;
    for (std::size_t c = 0; c < tables.size(); ++c) {
      const double area_px = std::numbers::pi * d * d / 4.0 / (object_pixel_um[c] * object_pixel_um[c]);
      removed += (1.0 - tables[c].tau(d)) * area_px;
    }
    removed /= static_cast<double>(tables.size());
    // tau grows with d, but never fast enough to undo d^2: kept non-decreasing for the inverse.
    if (!removed_.empty()) removed = std::max(removed, removed_.back());
    d_.push_back(d);
    removed_.push_back(removed);
  }
}

double DropletSizeModel::removed_px(double d_um) const { return interpolate(d_, removed_, d_um); }

double DropletSizeModel::diameter_um(double removed_px) const {
  if (!(removed_px > 0)) return 0;
  // Below the first step the shadow is opaque enough that removed ~ d^2.
  if (removed_px <= removed_.front()) return d_.front() * std::sqrt(removed_px / removed_.front());
  return interpolate(removed_, d_, removed_px);
}

}  // namespace tomorig::optics
