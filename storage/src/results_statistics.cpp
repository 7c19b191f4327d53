// Ensemble statistics of a results file, one set at a time: Welford's running mean and
// co-moment update, which avoids the cancellation of the sum-of-squares formula on small
// fluctuations as a second pass would, but needs no second pass over the sets (a file of
// thousands of sets is never held in memory).
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::storage {

double velocity_m_per_s(double voxels, double voxel_size_mm, std::int64_t dt_ns) {
  return voxels * voxel_size_mm * 1e-3 / (static_cast<double>(dt_ns) * 1e-9);
}

void EnsembleAccumulator::check(const SetResult& r) const {
  const VectorField& f = r.field;
  if (f.displacement.size() != f.count() || f.status.size() != f.count() || f.peak.size() != f.count())
    throw bad_input(fmt::format("set {}: the vector field's arrays do not match its {} x {} x {} nodes", r.set_index,
                                f.nx, f.ny, f.nz));
  if (sets_ > 0 && (f.nx != nx_ || f.ny != ny_ || f.nz != nz_))
    throw bad_input(fmt::format("set {} has a {} x {} x {} vector field but set {} has {} x {} x {}; the sets of "
                                "one results file must share their interrogation grid",
                                r.set_index, f.nx, f.ny, f.nz, first_set_, nx_, ny_, nz_));
  if (r.dt_ns <= 0)
    throw bad_input(fmt::format("set {} has pulse separation dt = {} ns; it must be > 0 to give velocities",
                                r.set_index, r.dt_ns));
}

void EnsembleAccumulator::add(const SetResult& r) {
  check(r);
  const VectorField& f = r.field;
  const std::size_t n = f.count();
  if (sets_ == 0) {
    nx_ = f.nx;
    ny_ = f.ny;
    nz_ = f.nz;
    origin_ = f.origin;
    spacing_ = f.spacing;
    first_set_ = r.set_index;
    count_.assign(n, 0);
    mean_displacement_.assign(n, Vec3d{});
    mean_velocity_.assign(n, Vec3d{});
    comoment_.assign(n, {});
  }
  ++sets_;
  const double to_velocity = velocity_m_per_s(1.0, voxel_size_mm_, r.dt_ns);
  for (std::size_t i = 0; i < n; ++i) {
    if (f.status[i] == VectorStatus::invalid) continue;  // valid and replaced vectors count
    const double c = ++count_[i];
    const Vec3f& d32 = f.displacement[i];
    const Vec3d d{d32.x, d32.y, d32.z};
    mean_displacement_[i] = mean_displacement_[i] + (d - mean_displacement_[i]) * (1.0 / c);
    const Vec3d u = d * to_velocity;
    const Vec3d before = u - mean_velocity_[i];
    mean_velocity_[i] = mean_velocity_[i] + before * (1.0 / c);
    const Vec3d after = u - mean_velocity_[i];
    auto& m = comoment_[i];
    m[0] += before.x * after.x;
    m[1] += before.y * after.y;
    m[2] += before.z * after.z;
    m[3] += before.x * after.y;
    m[4] += before.x * after.z;
    m[5] += before.y * after.z;
  }
}

EnsembleStatistics EnsembleAccumulator::result() const {
  EnsembleStatistics s;
  s.sets = sets_;
  if (sets_ == 0) return s;
  s.nx = nx_;
  s.ny = ny_;
  s.nz = nz_;
  s.origin = origin_;
  s.spacing = spacing_;
  const std::size_t n = count_.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s.valid_count = count_;
  s.mean_displacement_voxel.assign(n, Vec3d{nan, nan, nan});
  s.mean_velocity.assign(n, Vec3d{nan, nan, nan});
  s.rms_velocity.assign(n, Vec3d{nan, nan, nan});
  std::array<double, 6> none;
  none.fill(nan);
  s.reynolds_stress.assign(n, none);
  for (std::size_t i = 0; i < n; ++i) {
    if (count_[i] == 0) continue;
    s.mean_displacement_voxel[i] = mean_displacement_[i];
    s.mean_velocity[i] = mean_velocity_[i];
    auto& t = s.reynolds_stress[i];
    for (int k = 0; k < 6; ++k) t[k] = comoment_[i][k] / count_[i];
    s.rms_velocity[i] = {std::sqrt(t[0]), std::sqrt(t[1]), std::sqrt(t[2])};
  }
  return s;
}

EnsembleStatistics EnsembleStatistics::compute(const std::vector<SetResult>& sets, double voxel_size_mm) {
  EnsembleAccumulator a(voxel_size_mm);
  for (const SetResult& r : sets) a.add(r);
  return a.result();
}

}  // namespace tomorig::storage
