// Classical MART (Eq. 3.6; Elsinga et al.): camera by camera and, within a camera, ray by ray
// (pixel by pixel): each pixel's projection is recomputed from the current intensities and
// every voxel on it is corrected at once by (I_i / I~_i)^(mu w_ij). A zero pixel therefore
// zeroes every voxel it sees. The slow, sequential reference against which the fast schemes are
// judged. It starts from 1 in every voxel that every camera sees as non-zero (MLOS with a zero
// threshold): the voxels outside are exactly those classical MART zeroes on its first pass.
#include <cmath>

#include "algorithms.h"
#include "sparse_system.h"
#include "support.h"

namespace tomorig::recon::detail {
namespace {

// The transpose of the voxel -> pixel patches of one camera: for every pixel, the voxels that
// reach it and their weights (compressed rows).
struct RayTable {
  std::vector<std::uint32_t> start;  // padded pixel -> first entry; one past the end at the back
  std::vector<std::uint32_t> voxel;
  std::vector<float> weight;
};

RayTable rays_of(const SparseSystem& system, std::size_t c) {
  const int p = system.patch(), stride = system.stride(c);
  const std::size_t pixels = system.measured(c).size();
  RayTable t;
  t.start.assign(pixels + 1, 0);
  auto for_each_entry = [&](auto&& visit) {
    for (std::size_t n = 0; n < system.voxels(); ++n) {
      const SparseSystem::Patch patch = system.patch_of(c, n);
      for (int b = 0; b < p; ++b)
        for (int a = 0; a < p; ++a) {
          const std::int32_t pixel = patch.offset + b * stride + a;
          if (system.inside(c, pixel)) visit(n, pixel, patch.weight(a, b));
        }
    }
  };
  for_each_entry([&](std::size_t, std::int32_t pixel, float) { ++t.start[pixel + 1]; });
  for (std::size_t i = 0; i < pixels; ++i) t.start[i + 1] += t.start[i];
  t.voxel.resize(t.start.back());
  t.weight.resize(t.start.back());
  std::vector<std::uint32_t> fill(t.start.begin(), t.start.end() - 1);
  for_each_entry([&](std::size_t n, std::int32_t pixel, float w) {
    const std::uint32_t slot = fill[pixel]++;
    t.voxel[slot] = static_cast<std::uint32_t>(n);
    t.weight[slot] = w;
  });
  return t;
}

class MartReconstructor final : public Reconstructor {
 public:
  explicit MartReconstructor(const ReconstructionOptions& options) : options_(options) {}
  std::string name() const override { return "mart"; }

 protected:
  SparseVolume run(const ReconstructionInput& input, ReconstructionReport& report) override {
    SupportNeeds needs;
    needs.mlos_threshold = 0.0;
    needs.positions = true;
    const int p = options_.patch_size > 0 ? options_.patch_size : 4;
    needs.extra_bytes_per_voxel = static_cast<double>(input.cameras.size()) * p * p * 8.0;
    Support s = build_support(input, options_, needs, report);
    SparseSystem system(s.in, s.set.index, *s.projector, s.patch, options_.lut_steps);
    std::vector<RayTable> rays;
    for (std::size_t c = 0; c < system.cameras(); ++c) rays.push_back(rays_of(system, c));
    std::vector<float> e(system.voxels(), 1.0f);
    report.setup_seconds = elapsed_seconds();
    report.threads = 1;  // ray by ray: sequential by definition

    const double mu = options_.relaxation;
    for (int it = 1; it <= options_.max_iterations; ++it) {
      const auto t0 = std::chrono::steady_clock::now();
      double diff = 0, measured_sum = 0, update_sum = 0, updates = 0;
      for (std::size_t c = 0; c < system.cameras(); ++c) {
        const RayTable& t = rays[c];
        const std::vector<float>& measured = system.measured(c);
        for (std::size_t pixel = 0; pixel < measured.size(); ++pixel) {
          const double i_meas = measured[pixel];
          if (!system.inside(c, static_cast<std::int32_t>(pixel))) continue;
          double i_proj = 0;
          for (std::uint32_t q = t.start[pixel]; q < t.start[pixel + 1]; ++q) i_proj += t.weight[q] * e[t.voxel[q]];
          diff += std::fabs(i_meas - i_proj);
          measured_sum += i_meas;
          if (!(i_proj > 0)) continue;  // no live voxel on this ray: nothing to correct
          const double ratio = i_meas / i_proj;
          for (std::uint32_t q = t.start[pixel]; q < t.start[pixel + 1]; ++q) {
            const double factor = std::pow(ratio, mu * t.weight[q]);
            e[t.voxel[q]] = static_cast<float>(e[t.voxel[q]] * factor);
            update_sum += std::fabs(1.0 - factor);
            updates += 1;
          }
        }
      }
      if (record_iteration(report, it, measured_sum > 0 ? diff / measured_sum : 0.0,
                           updates > 0 ? update_sum / updates : 0.0, seconds_since(t0), options_.stop_mean_update))
        break;
    }
    SparseVolume volume = to_volume(s.in.grid, s.set.index, e);
    return volume;
  }

 private:
  ReconstructionOptions options_;
};

}  // namespace

std::unique_ptr<Reconstructor> make_mart(const ReconstructionOptions& options) {
  return std::make_unique<MartReconstructor>(options);
}

}  // namespace tomorig::recon::detail
