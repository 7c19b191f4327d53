#pragma once
// The reconstruction settings `bench recon`, `bench recon-race` and `bench piv3d` share: the
// weight sigma of every camera and the pruning fraction. One place registers, applies and
// reports them, so the three commands read them the same way.
#include <nlohmann/json.hpp>

#include "tomorig/processing/reconstruction/reconstructor.h"

namespace CLI {
class App;
}

namespace tomorig::bench {

struct BenchReconTuning {
  double sigma_px = 0.0;         // weight sigma, pixels, all cameras; 0: the library default
  double prune_fraction = -1.0;  // < 0: the library default

  // Registers --sigma-px and --prune.
  void add_options(CLI::App& cmd);
  void apply(recon::ReconstructionOptions& options) const;
  void apply(recon::ReconstructionInput& input) const;
  // The pruning fraction in effect (the library default resolved).
  double prune_in_effect() const;
  // The sigma for the JSON header: the number given, or "default".
  nlohmann::json sigma_json() const;
};

}  // namespace tomorig::bench
