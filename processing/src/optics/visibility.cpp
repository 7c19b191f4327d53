#include "tomorig/processing/optics/visibility.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"

namespace tomorig::optics {

double CameraOptics::chi_at(double z_mm) const {
  if (chi.empty()) return std::nan("");
  if (chi.size() == 1) return z_mm == chi[0].z_mm ? chi[0].chi_um : std::nan("");
  if (z_mm < chi.front().z_mm || z_mm > chi.back().z_mm) return std::nan("");
  std::size_t i = 1;
  while (i + 1 < chi.size() && chi[i].z_mm < z_mm) ++i;
  const ChiSample& lo = chi[i - 1];
  const ChiSample& hi = chi[i];
  const double t = (z_mm - lo.z_mm) / (hi.z_mm - lo.z_mm);
  return lo.chi_um + t * (hi.chi_um - lo.chi_um);
}

void VisibilitySetup::validate() const {
  spectrum.validate();
  if (cameras.empty()) throw bad_input("optics set-up: no cameras");
  if (!(d_max_um > 1.0 && d_max_um <= 2000.0))
    throw bad_input(fmt::format("optics set-up: d_max_um = {} must be in (1, 2000]", d_max_um));
  for (const CameraOptics& c : cameras) {
    const std::string who = fmt::format("optics set-up: camera '{}'", c.id);
    if (!(c.f_number > 0.0 && c.f_number < 1000.0)) throw bad_input(fmt::format("{}: f_number = {} must be > 0", who, c.f_number));
    if (!(c.magnification > 0.0 && c.magnification < 100.0))
      throw bad_input(fmt::format("{}: magnification = {} must be > 0", who, c.magnification));
    if (!(c.noise_sigma > 0.0 && c.noise_sigma < 0.5))
      throw bad_input(fmt::format("{}: noise = {} must be in (0, 0.5) (sigma of the flat-fielded bright field; "
                                  "the threshold of visibility is 1 - 2 sigma)",
                                  who, c.noise_sigma));
    if (c.chi.empty()) throw bad_input(fmt::format("{}: no PSF half-widths (chi_um at z_mm)", who));
    for (std::size_t i = 0; i < c.chi.size(); ++i) {
      if (!(c.chi[i].chi_um > 0.0) || !std::isfinite(c.chi[i].chi_um))
        throw bad_input(fmt::format("{}: chi_um = {} at z = {} mm must be > 0", who, c.chi[i].chi_um, c.chi[i].z_mm));
      if (!std::isfinite(c.chi[i].z_mm) || (i > 0 && !(c.chi[i].z_mm > c.chi[i - 1].z_mm)))
        throw bad_input(fmt::format("{}: z_mm must be finite and strictly ascending (z = {} after {})", who,
                                    c.chi[i].z_mm, i > 0 ? c.chi[i - 1].z_mm : 0.0));
    }
  }
}

TransmissionTable::TransmissionTable(const TransmissionModel& model, double na, double d_max_um) : na_(na) {
  for (double d = 0.5; d < d_max_um + 1e-9;) {
    d_.push_back(d);
    tau_.push_back(model.transmission(d, na));
    d += d < 50.0 ? 0.5 : 1.0;
  }
  if (d_.back() < d_max_um) {
    d_.push_back(d_max_um);
    tau_.push_back(model.transmission(d_max_um, na));
  }
}

double TransmissionTable::tau(double d_um) const {
  // Below the first node tau goes to 0 with d (Rayleigh: all but a sliver scattered outside).
  if (d_um <= d_.front()) return tau_.front() * std::max(0.0, d_um) / d_.front();
  if (d_um >= d_.back()) return tau_.back();
  const auto it = std::upper_bound(d_.begin(), d_.end(), d_um);
  const std::size_t i = static_cast<std::size_t>(it - d_.begin());
  const double t = (d_um - d_[i - 1]) / (d_[i] - d_[i - 1]);
  return tau_[i - 1] + t * (tau_[i] - tau_[i - 1]);
}

double smallest_visible_diameter(const TransmissionTable& table, double chi_um, double threshold) {
  const auto visible = [&](double d) { return minimum_intensity(d, chi_um, table.tau(d)) <= threshold; };
  // The minimum intensity is not monotonic in d (a sharp PSF gives a dip below the plateau,
  // Fig. 6.6), so scan upwards for the first visible size, then bisect below it.
  constexpr double kStep = 0.25;
  double lo = 0.0;
  for (double d = kStep; d <= table.d_max() + 1e-9; d += kStep) {
    if (visible(d)) {
      double hi = d;
      while (hi - lo > 0.01) {
        const double mid = 0.5 * (lo + hi);
        (visible(mid) ? hi : lo) = mid;
      }
      return hi;
    }
    lo = d;
  }
  return kNotVisible;
}

std::vector<VisibilityRow> visibility_table(const VisibilitySetup& setup) {
  setup.validate();
  const TransmissionModel model(setup.liquid, setup.spectrum);
  std::map<double, TransmissionTable> tables;  // one per distinct aperture
  std::vector<const TransmissionTable*> table_of;
  for (const CameraOptics& c : setup.cameras) {
    const double na = object_numerical_aperture(c.f_number, c.magnification);
    auto it = tables.find(na);
    if (it == tables.end()) it = tables.emplace(na, TransmissionTable(model, na, setup.d_max_um)).first;
    table_of.push_back(&it->second);
  }
  std::vector<double> zs;
  for (const CameraOptics& c : setup.cameras)
    for (const ChiSample& s : c.chi) zs.push_back(s.z_mm);
  std::sort(zs.begin(), zs.end());
  zs.erase(std::unique(zs.begin(), zs.end()), zs.end());

  std::vector<VisibilityRow> rows;
  for (double z : zs) {
    VisibilityRow row;
    row.z_mm = z;
    for (std::size_t c = 0; c < setup.cameras.size(); ++c) {
      const double chi = setup.cameras[c].chi_at(z);
      row.chi_um.push_back(chi);
      double d = std::nan("");
      if (std::isfinite(chi)) {
        d = smallest_visible_diameter(*table_of[c], chi, setup.cameras[c].threshold());
      }
      row.d_min_um.push_back(d);
    }
    row.setup_d_min_um = *std::max_element(row.d_min_um.begin(), row.d_min_um.end(), [](double a, double b) {
      return std::isnan(b) ? !std::isnan(a) : (!std::isnan(a) && a < b);
    });
    rows.push_back(std::move(row));
  }
  return rows;
}

double bright_field_noise(std::span<const Image> frames) {
  if (frames.size() < 2)
    throw bad_input(fmt::format("bright-field noise needs at least 2 frames without spray, got {}", frames.size()));
  const int w = frames[0].width(), h = frames[0].height();
  for (const Image& f : frames)
    if (f.width() != w || f.height() != h || f.empty())
      throw bad_input(fmt::format("bright-field frames differ in size ({} x {} and {} x {})", w, h, f.width(), f.height()));
  const std::size_t n = frames.size();
  std::vector<double> mean(static_cast<std::size_t>(w) * h, 0.0);
  for (const Image& f : frames)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) mean[static_cast<std::size_t>(y) * w + x] += f.value(x, y) / n;
  double sum = 0.0, sum2 = 0.0;
  for (const Image& f : frames)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double m = mean[static_cast<std::size_t>(y) * w + x];
        if (!(m > 0.0))
          throw bad_input(fmt::format("bright-field frames: pixel ({}, {}) has mean {} <= 0: not a lit bright field", x, y, m));
        const double v = f.value(x, y) / m;
        sum += v;
        sum2 += v * v;
      }
  const double count = static_cast<double>(n) * w * h;
  const double var = std::max(0.0, sum2 / count - (sum / count) * (sum / count));
  return std::sqrt(var * static_cast<double>(n) / static_cast<double>(n - 1));
}

}  // namespace tomorig::optics
