#include "tomorig/processing/reconstruction/reconstructor.h"

#include <cmath>

#include <fmt/core.h>

#include "algorithms.h"
#include "ment.h"
#include "support.h"
#include "system_memory.h"
#include "tomorig/core/error.h"

namespace tomorig::recon {

void ReconstructionOptions::validate() const {
  // Written as !(a < x) so that NaN fails too.
  if (max_iterations < 1)
    throw bad_input(fmt::format("reconstruction: max_iterations = {} must be >= 1", max_iterations));
  if (!(relaxation > 0 && relaxation <= 2))
    throw bad_input(fmt::format("reconstruction: relaxation = {} is out of range: mu must be in (0, 2]", relaxation));
  if (!(stop_mean_update >= 0) || !std::isfinite(stop_mean_update))
    throw bad_input(fmt::format("reconstruction: stop_mean_update = {} must be >= 0 (0: run max_iterations)",
                                stop_mean_update));
  if (!(mlos_threshold >= 0 && mlos_threshold < 1))
    throw bad_input(fmt::format("reconstruction: mlos_threshold = {} must be in [0, 1) (a fraction of each image's "
                                "maximum)",
                                mlos_threshold));
  if (lut_steps < 50 || lut_steps > 1024)
    throw bad_input(fmt::format("reconstruction: lut_steps = {} must be in [50, 1024] sub-pixel steps per pixel",
                                lut_steps));
  if (patch_size < 0 || patch_size > 16)
    throw bad_input(fmt::format("reconstruction: patch_size = {} must be in [1, 16] px, or 0 for ceil(4 sigma)",
                                patch_size));
  if (!(prune_fraction >= 0 && prune_fraction < 1))
    throw bad_input(fmt::format("reconstruction: prune_fraction = {} must be in [0, 1) (a fraction of the largest "
                                "intensity; 0: never prune)",
                                prune_fraction));
  if (threads < 0) throw bad_input(fmt::format("reconstruction: threads = {} must be >= 0 (0: default)", threads));
  if (!(memory_limit_mb >= 0) || !std::isfinite(memory_limit_mb))
    throw bad_input(fmt::format("reconstruction: memory_limit_mb = {} must be >= 0 (0: MemAvailable)", memory_limit_mb));
}

SparseVolume Reconstructor::reconstruct(const ReconstructionInput& input, ReconstructionReport& report) {
  start_ = std::chrono::steady_clock::now();
  observer_seconds_ = 0.0;
  report = {};
  report.algorithm = name();
  SparseVolume volume = run(input, report);
  report.nonzero_voxels = volume.size();
  report.observer_seconds = observer_seconds_;
  report.seconds = elapsed_seconds();
  report.peak_rss_mb = detail::peak_rss_mb();
  return volume;
}

double Reconstructor::elapsed_seconds() const { return detail::seconds_since(start_) - observer_seconds_; }

void Reconstructor::notify(int iteration, const IterationStats* stats, std::function<SparseVolume()> volume) {
  if (!observer_) return;
  const auto t0 = std::chrono::steady_clock::now();
  IterationView view;
  view.iteration = iteration;
  view.stats = stats;
  view.elapsed_seconds = elapsed_seconds();
  view.volume = std::move(volume);
  observer_(view);
  observer_seconds_ += detail::seconds_since(t0);
}

std::string algorithm_names() { return "mlos, ment, mart, smart, fmart"; }

std::unique_ptr<Reconstructor> make_reconstructor(const ReconstructionOptions& options) {
  options.validate();
  const std::string& a = options.algorithm;
  if (a == "mlos") return detail::make_mlos(options);
  if (a == "mart") return detail::make_mart(options);
  if (a == "smart") return detail::make_smart(options);
  if (a == "fmart") return detail::make_fmart(options);
  if (a == "ment") return detail::make_ment(options);
  throw bad_input(fmt::format("reconstruction: unknown algorithm '{}'; use one of: {}", a, algorithm_names()));
}

std::string ReconstructionReport::brief() const {
  const double last_residual = history.empty() ? 0.0 : history.back().residual;
  const double last_update = history.empty() ? 0.0 : history.back().mean_update;
  return fmt::format("{}: {} iterations, {} active voxels, {} non-zero, residual {:.4f}, mean update {:.4f}, "
                     "{:.3f} s (set-up {:.3f} s), peak RSS {:.0f} MB, {} threads",
                     algorithm, iterations, active_voxels, nonzero_voxels, last_residual, last_update, seconds,
                     setup_seconds, peak_rss_mb, threads);
}

}  // namespace tomorig::recon
