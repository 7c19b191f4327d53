// FMART (Sect. 3.1.3, Eq. 3.9) and SMART (Sect. 3.1.2, Eq. 3.5) on the same sparse machinery:
// the MLOS support, precomputed patches and LUT weights (SparseSystem). They differ only in
// when the voxels are updated:
//   FMART: camera by camera, project that camera then update every voxel by
//          P_j^m = prod_i R_i^(mu w_ij) (Eq. 3.9), so the next camera sees the update;
//   SMART: project every camera from the same intensities, then update once by the weighted
//          geometric mean over all cameras, prod_m prod_i R_i^(mu w_ij / M) (Eq. 3.5, with
//          1/N_i taken as 1/M: each camera's weights sum to ~1).
// Both prune the same way (options.prune_fraction), so their times per iteration compare the
// algorithms, not the care taken over each.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "algorithms.h"
#include "fast_math.h"
#include "sparse_system.h"
#include "stage_timer.h"
#include "support.h"

namespace tomorig::recon::detail {
namespace {

enum class Schedule { by_camera, simultaneous };

constexpr double kInitialPruneShare = 0.1;

// Sets voxels below `fraction` of the largest intensity to 0; returns how many are > 0.
std::size_t zero_faint(std::vector<float>& e, double fraction, int threads) {
  const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(e.size());
  float largest = 0.0f;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(max : largest)
  for (std::ptrdiff_t n = 0; n < count; ++n) largest = std::max(largest, e[n]);
  const float cut = static_cast<float>(fraction) * largest;
  std::size_t live = 0;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : live)
  for (std::ptrdiff_t n = 0; n < count; ++n) {
    if (e[n] < cut) e[n] = 0.0f;
    live += e[n] > 0.0f;
  }
  return live;
}

// Removes the voxels of `set` whose value is below `fraction` of the largest, in place.
void drop_faint(ActiveSet& set, double fraction) {
  float largest = 0.0f;
  for (float v : set.value) largest = std::max(largest, v);
  const float cut = static_cast<float>(fraction) * largest;
  std::size_t kept = 0;
  for (std::size_t n = 0; n < set.size(); ++n) {
    if (set.value[n] < cut) continue;
    set.index[kept] = set.index[n];
    set.value[kept] = set.value[n];
    ++kept;
  }
  set.index.resize(kept);
  set.value.resize(kept);
}

class MultiplicativeReconstructor final : public Reconstructor {
 public:
  MultiplicativeReconstructor(const ReconstructionOptions& options, Schedule schedule)
      : options_(options), schedule_(schedule) {}
  std::string name() const override { return schedule_ == Schedule::by_camera ? "fmart" : "smart"; }

 protected:
  SparseVolume run(const ReconstructionInput& input, ReconstructionReport& report) override {
    StageTimer timer(schedule_ == Schedule::by_camera ? "fmart" : "smart");
    SupportNeeds needs;
    needs.mlos_threshold = options_.mlos_threshold;
    needs.positions = true;
    Support s = build_support(input, options_, needs, report, &mlos_buffers_);
    const int threads = s.in.threads;

    // Starting from the MLOS intensities, a voxel far below the prune fraction of the largest
    // is dropped before the system is built: its share of every projection is as small as its
    // intensity, and each one costs 8 bytes per camera of freshly touched memory and a visit
    // per projection. A tenth of the fraction, because the faint ghosts still matter in the
    // first iteration: dropping at the full fraction cost 0.005 in Q (tpiv-thesis, 0.05 ppp),
    // a tenth costs nothing measurable and removes 60 % of them (docs/reconstruction.md).
    if (options_.mlos_initial_intensity && options_.prune_fraction > 0)
      drop_faint(s.set, kInitialPruneShare * options_.prune_fraction);
    SparseSystem system(s.in, s.set.index, *s.projector, s.patch, options_.lut_steps,
                        spare_system_ ? &*spare_system_ : nullptr);
    std::vector<std::uint32_t> index = std::move(s.set.index);
    std::vector<float> e = std::move(s.set.value);
    if (!options_.mlos_initial_intensity) std::fill(e.begin(), e.end(), 1.0f);
    std::vector<float> acc(schedule_ == Schedule::simultaneous ? e.size() : 0);
    timer.mark("sparse system");

    auto current_volume = [&] { return to_volume(s.in.grid, index, e); };
    report.setup_seconds = elapsed_seconds();
    notify(0, nullptr, current_volume);

    const float mu = static_cast<float>(options_.relaxation);
    const std::size_t cams = system.cameras();
    for (int it = 1; it <= options_.max_iterations; ++it) {
      const auto t0 = std::chrono::steady_clock::now();
      const double updates =
          std::max<double>(1.0, static_cast<double>(e.size()) * (schedule_ == Schedule::by_camera ? cams : 1));
      double diff = 0, measured = 0, update_sum = 0;
      if (schedule_ == Schedule::by_camera) {
        for (std::size_t c = 0; c < cams; ++c) {
          const PixelResidual r = system.project(c, e.data(), threads);
          diff += r.abs_difference;
          measured += r.measured;
          update_sum += system.update(c, e.data(), mu, threads);
        }
      } else {
        std::fill(acc.begin(), acc.end(), 0.0f);
        for (std::size_t c = 0; c < cams; ++c) {
          const PixelResidual r = system.project(c, e.data(), threads);
          diff += r.abs_difference;
          measured += r.measured;
          system.accumulate(c, acc.data(), threads);
        }
        const float scale = mu / static_cast<float>(cams);
        const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(e.size());
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : update_sum)
        for (std::ptrdiff_t n = 0; n < count; ++n) {
          if (e[n] == 0.0f) continue;
          const float factor = fast_exp(scale * acc[n]);
          e[n] *= factor;
          update_sum += std::fabs(1.0f - factor);
        }
      }
      if (options_.prune_fraction > 0) prune(system, index, e, acc, threads);
      const bool stop = record_iteration(report, it, measured > 0 ? diff / measured : 0.0, update_sum / updates,
                                         seconds_since(t0), options_.stop_mean_update);
      report.history.back().elapsed_seconds = elapsed_seconds();
      report.history.back().live_voxels = e.size();
      timer.mark("iteration");
      notify(it, &report.history.back(), current_volume);
      if (stop) break;
    }
    SparseVolume volume = to_volume(s.in.grid, index, e);
    // The next run (the other exposure, the next set) fills the same memory.
    mlos_buffers_.spare.index = std::move(index);
    mlos_buffers_.spare.value = std::move(e);
    spare_system_.emplace(std::move(system));
    timer.mark("output");
    return volume;
  }

 private:
  // Zeroes the voxels below prune_fraction of the largest and, once they are at least a tenth
  // of the list, drops them from it (and from the system), so that later iterations stream
  // only live voxels.
  void prune(SparseSystem& system, std::vector<std::uint32_t>& index, std::vector<float>& e, std::vector<float>& acc,
             int threads) const {
    const std::size_t live = zero_faint(e, options_.prune_fraction, threads);
    if (live + e.size() / 10 > e.size()) return;
    std::vector<std::uint32_t> kept;
    kept.reserve(live);
    for (std::size_t n = 0; n < e.size(); ++n)
      if (e[n] > 0.0f) kept.push_back(static_cast<std::uint32_t>(n));
    system.compact(kept, threads);
    for (std::size_t n = 0; n < kept.size(); ++n) {
      index[n] = index[kept[n]];
      e[n] = e[kept[n]];
    }
    index.resize(kept.size());
    e.resize(kept.size());
    if (!acc.empty()) acc.resize(kept.size());
  }

  ReconstructionOptions options_;
  Schedule schedule_;
  // Kept between runs: on this machine touching fresh memory costs more than filling it
  // (docs/performance.md, "Page faults"); about 55 bytes per active voxel.
  MlosBuffers mlos_buffers_;
  std::optional<SparseSystem> spare_system_;
};

}  // namespace

std::unique_ptr<Reconstructor> make_fmart(const ReconstructionOptions& options) {
  return std::make_unique<MultiplicativeReconstructor>(options, Schedule::by_camera);
}
std::unique_ptr<Reconstructor> make_smart(const ReconstructionOptions& options) {
  return std::make_unique<MultiplicativeReconstructor>(options, Schedule::simultaneous);
}

}  // namespace tomorig::recon::detail
