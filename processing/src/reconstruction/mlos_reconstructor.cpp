// MLOS as a reconstructor in its own right: the support and its product intensities.
#include <algorithm>
#include <utility>

#include "algorithms.h"
#include "support.h"

namespace tomorig::recon::detail {
namespace {

class MlosReconstructor final : public Reconstructor {
 public:
  explicit MlosReconstructor(const ReconstructionOptions& options) : options_(options) {}
  std::string name() const override { return "mlos"; }

 protected:
  SparseVolume run(const ReconstructionInput& input, ReconstructionReport& report) override {
    SupportNeeds needs;
    needs.mlos_threshold = options_.mlos_threshold;
    needs.positions = false;
    Support s = build_support(input, options_, needs, report);
    // MLOS keeps only voxels whose every read is > 0, so the support is normally the volume
    // itself: hand its arrays over instead of copying them into fresh (first-touched) memory.
    SparseVolume volume;
    if (std::all_of(s.set.value.begin(), s.set.value.end(), [](float e) { return e > 0.0f; })) {
      volume.grid = s.in.grid;
      volume.index = std::move(s.set.index);
      volume.intensity = std::move(s.set.value);
    } else {
      volume = to_volume(s.in.grid, s.set.index, s.set.value);
    }
    return volume;
  }

 private:
  ReconstructionOptions options_;
};

}  // namespace

std::unique_ptr<Reconstructor> make_mlos(const ReconstructionOptions& options) {
  return std::make_unique<MlosReconstructor>(options);
}

}  // namespace tomorig::recon::detail
