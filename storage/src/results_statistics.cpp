// Ensemble statistics of a results file: one pass for the sums, one for the fluctuations
// (two passes avoid the cancellation of the sum-of-squares formula on small fluctuations).
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::storage {

double velocity_m_per_s(double voxels, double voxel_size_mm, std::int64_t dt_ns) {
  return voxels * voxel_size_mm * 1e-3 / (static_cast<double>(dt_ns) * 1e-9);
}

EnsembleStatistics EnsembleStatistics::compute(const std::vector<SetResult>& sets, double voxel_size_mm) {
  EnsembleStatistics s;
  s.sets = sets.size();
  if (sets.empty()) return s;
  const VectorField& first = sets.front().field;
  s.nx = first.nx;
  s.ny = first.ny;
  s.nz = first.nz;
  s.origin = first.origin;
  s.spacing = first.spacing;
  const std::size_t n = first.count();
  for (const SetResult& r : sets) {
    if (r.field.nx != s.nx || r.field.ny != s.ny || r.field.nz != s.nz || r.field.displacement.size() != n ||
        r.field.status.size() != n)
      throw bad_input(fmt::format("set {} has a {} x {} x {} vector field but set {} has {} x {} x {}; the sets of "
                                  "one results file must share their interrogation grid",
                                  r.set_index, r.field.nx, r.field.ny, r.field.nz, sets.front().set_index, s.nx, s.ny,
                                  s.nz));
    if (r.dt_ns <= 0)
      throw bad_input(fmt::format("set {} has pulse separation dt = {} ns; it must be > 0 to give velocities",
                                  r.set_index, r.dt_ns));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s.valid_count.assign(n, 0);
  s.mean_displacement_voxel.assign(n, Vec3d{});
  s.mean_velocity.assign(n, Vec3d{});
  s.rms_velocity.assign(n, Vec3d{});
  s.reynolds_stress.assign(n, {});
  const auto counts = [](VectorStatus st) { return st != VectorStatus::invalid; };
  const auto velocity = [&](const SetResult& r, std::size_t i) {
    const Vec3f& d = r.field.displacement[i];
    return Vec3d{velocity_m_per_s(d.x, voxel_size_mm, r.dt_ns), velocity_m_per_s(d.y, voxel_size_mm, r.dt_ns),
                 velocity_m_per_s(d.z, voxel_size_mm, r.dt_ns)};
  };
  for (const SetResult& r : sets)
    for (std::size_t i = 0; i < n; ++i) {
      if (!counts(r.field.status[i])) continue;
      ++s.valid_count[i];
      const Vec3f& d = r.field.displacement[i];
      s.mean_displacement_voxel[i] = s.mean_displacement_voxel[i] + Vec3d{d.x, d.y, d.z};
      s.mean_velocity[i] = s.mean_velocity[i] + velocity(r, i);
    }
  for (std::size_t i = 0; i < n; ++i) {
    if (s.valid_count[i] == 0) {
      s.mean_displacement_voxel[i] = s.mean_velocity[i] = s.rms_velocity[i] = {nan, nan, nan};
      s.reynolds_stress[i].fill(nan);
      continue;
    }
    const double inv = 1.0 / s.valid_count[i];
    s.mean_displacement_voxel[i] = s.mean_displacement_voxel[i] * inv;
    s.mean_velocity[i] = s.mean_velocity[i] * inv;
  }
  for (const SetResult& r : sets)
    for (std::size_t i = 0; i < n; ++i) {
      if (!counts(r.field.status[i])) continue;
      const Vec3d u = velocity(r, i) - s.mean_velocity[i];
      auto& t = s.reynolds_stress[i];
      t[0] += u.x * u.x;
      t[1] += u.y * u.y;
      t[2] += u.z * u.z;
      t[3] += u.x * u.y;
      t[4] += u.x * u.z;
      t[5] += u.y * u.z;
    }
  for (std::size_t i = 0; i < n; ++i) {
    if (s.valid_count[i] == 0) continue;
    auto& t = s.reynolds_stress[i];
    for (double& v : t) v /= s.valid_count[i];
    s.rms_velocity[i] = {std::sqrt(t[0]), std::sqrt(t[1]), std::sqrt(t[2])};
  }
  return s;
}

}  // namespace tomorig::storage
