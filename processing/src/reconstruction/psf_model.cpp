#include "tomorig/processing/reconstruction/psf_model.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::recon {

PsfSample PsfModel::at(double z_mm) const {
  if (samples.empty()) return {};
  if (z_mm <= samples.front().z_mm) return samples.front();
  if (z_mm >= samples.back().z_mm) return samples.back();
  const auto upper = std::upper_bound(samples.begin(), samples.end(), z_mm,
                                      [](double z, const PsfSample& s) { return z < s.z_mm; });
  const PsfSample& b = *upper;
  const PsfSample& a = *(upper - 1);
  const double t = (z_mm - a.z_mm) / (b.z_mm - a.z_mm);
  return {z_mm, a.sigma_u_px + t * (b.sigma_u_px - a.sigma_u_px), a.sigma_v_px + t * (b.sigma_v_px - a.sigma_v_px),
          a.angle_rad + t * (b.angle_rad - a.angle_rad)};
}

double PsfModel::max_sigma() const {
  double m = 0;
  for (const PsfSample& s : samples) m = std::max({m, s.sigma_u_px, s.sigma_v_px});
  return m;
}

void PsfModel::validate(const std::string& what) const {
  if (samples.empty()) throw bad_input(fmt::format("{}: no samples: give at least one (z, sigma_u, sigma_v)", what));
  for (std::size_t n = 0; n < samples.size(); ++n) {
    const PsfSample& s = samples[n];
    if (!std::isfinite(s.z_mm)) throw bad_input(fmt::format("{}: sample {} has a non-finite z", what, n));
    if (n > 0 && !(s.z_mm > samples[n - 1].z_mm))
      throw bad_input(fmt::format("{}: sample {} has z = {} mm, not above the previous {} mm: list samples in "
                                  "strictly ascending z",
                                  what, n, s.z_mm, samples[n - 1].z_mm));
    if (!(std::fabs(s.angle_rad) <= 3.14159265358979323846))
      throw bad_input(fmt::format("{}: sample {} has angle = {} rad: it must be in [-pi, pi]", what, n, s.angle_rad));
    for (double sigma : {s.sigma_u_px, s.sigma_v_px})
      if (!(sigma > 0 && sigma <= 10))
        throw bad_input(fmt::format("{}: sample {} has sigma = {} px: it must be in (0, 10] px", what, n, sigma));
  }
}

}  // namespace tomorig::recon
