#include "bench_recon_tuning.h"

#include <CLI/CLI.hpp>

namespace tomorig::bench {

void BenchReconTuning::add_options(CLI::App& cmd) {
  cmd.add_option("--sigma-px", sigma_px,
                 "Gaussian sigma of the voxel-to-pixel weights, pixels, all cameras (0: the library default)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd.add_option("--prune", prune_fraction,
                 "SMART/FMART: drop voxels below this fraction of the largest intensity after each iteration "
                 "(0: never; negative: the library default)")
      ->capture_default_str();
}

void BenchReconTuning::apply(recon::ReconstructionOptions& options) const {
  options.prune_fraction = prune_in_effect();
}

void BenchReconTuning::apply(recon::ReconstructionInput& input) const {
  if (sigma_px > 0) input.psf.assign(input.cameras.size(), recon::PsfModel::constant(sigma_px));
}

double BenchReconTuning::prune_in_effect() const {
  return prune_fraction >= 0 ? prune_fraction : recon::ReconstructionOptions{}.prune_fraction;
}

nlohmann::json BenchReconTuning::sigma_json() const {
  return sigma_px > 0 ? nlohmann::json(sigma_px) : nlohmann::json("default");
}

}  // namespace tomorig::bench
