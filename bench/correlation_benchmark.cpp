// One full multi-grid correlation (binned 2x pass, integer-offset pass, two B-spline
// deformation passes at 75 % overlap) of a tpiv-thesis-sized 512 x 512 x 160 pair: 13 107
// particles (0.05 ppp; ~10 per 32^3 window, thesis Sect. 3.3-3.4), Taylor-Green displacement
// A = 5, p = 256 voxel. The 32^3 case is the tpiv-thesis scheme of `tomorig bench piv3d`.
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "tomorig/processing/correlation/correlate.h"
#include "tomorig/processing/quality/gaussian_blobs.h"
#include "tomorig/simulators/taylor_green.h"

namespace {

struct Pair {
  tomorig::DenseVolume a, b;
};

const Pair& thesis_pair() {
  static const Pair pair = [] {
    const tomorig::VoxelGrid grid = tomorig::VoxelGrid::centred(512, 512, 160, 0.0195);
    const tomorig::sim::TaylorGreenFlow flow(grid, 5.0, 256.0);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> ux(0, 511), uy(0, 511), uz(0, 159);
    const int count = 13107;  // 0.05 ppp of a 512 x 512 image
    std::vector<tomorig::Vec3d> pa, pb;
    for (int n = 0; n < count; ++n) {
      const tomorig::Vec3d x{ux(rng), uy(rng), uz(rng)};
      const tomorig::Vec3d d = flow.displacement_voxel(x);
      const tomorig::Vec3d xa = x - d * 0.5, xb = x + d * 0.5;
      pa.push_back(grid.centre_of(xa.x, xa.y, xa.z));
      pb.push_back(grid.centre_of(xb.x, xb.y, xb.z));
    }
    return Pair{tomorig::quality::gaussian_blob_volume(grid, pa).to_dense(),
                tomorig::quality::gaussian_blob_volume(grid, pb).to_dense()};
  }();
  return pair;
}

// Counters: the final node count, per pass its seconds and breakdown (deformation, windows,
// validation; load / correlation / peak in thread-seconds), and the FFT floor of the same
// scheme (the FFTs alone of the same windows, same threads) measured after the last
// iteration, with the ratio of the correlation to it.
void report_counters(benchmark::State& state, const tomorig::piv::CorrelationOptions& options,
                     const tomorig::piv::CorrelationReport& report) {
  const auto& last = report.passes.back();
  state.counters["nodes_final"] = static_cast<double>(last.nodes_x) * last.nodes_y * last.nodes_z;
  for (std::size_t p = 0; p < report.passes.size(); ++p) {
    const auto& r = report.passes[p];
    const std::string tag = "pass" + std::to_string(p);
    state.counters["s_" + tag] = r.seconds;
    state.counters["s_" + tag + "_deform"] = r.seconds_deformation;
    state.counters["s_" + tag + "_windows"] = r.seconds_windows;
    state.counters["s_" + tag + "_valid"] = r.seconds_validation;
    state.counters["ts_" + tag + "_load"] = r.thread_seconds_load;
    state.counters["ts_" + tag + "_corr"] = r.thread_seconds_correlation;
    state.counters["ts_" + tag + "_peak"] = r.thread_seconds_peak;
    state.counters["direct_" + tag] = std::string(r.method) == "direct";
    state.counters["occupied_" + tag] = r.occupied_fraction;
    state.counters["fallbacks_" + tag] = static_cast<double>(r.fft_fallbacks);
  }
  state.counters["valid_fraction"] = report.valid_fraction();
  const tomorig::piv::FftFloor floor = tomorig::piv::measure_fft_floor(thesis_pair().a.grid, options);
  state.counters["s_fft_floor"] = floor.seconds_total;
  state.counters["s_correlation"] = report.seconds_total;
  state.counters["ratio_to_floor"] = floor.seconds_total > 0 ? report.seconds_total / floor.seconds_total : 0.0;
}

void run(benchmark::State& state, const tomorig::piv::CorrelationOptions& options) {
  const Pair& pair = thesis_pair();
  tomorig::piv::CorrelationReport report;
  for (auto _ : state) {
    const auto field = tomorig::piv::correlate(pair.a, pair.b, options, report);
    benchmark::DoNotOptimize(field.displacement.data());
  }
  report_counters(state, options, report);
}

void run(benchmark::State& state, tomorig::piv::WindowSize window) {
  auto options = tomorig::piv::CorrelationOptions::multigrid(window, 0.75, 2);
  options.weighting = tomorig::piv::WindowWeighting::gaussian;  // as the CLI (process, piv3d)
  options.gaussian_sigma = 0.5;
  options.threads = static_cast<int>(state.range(0));
  run(state, options);
}

// One pass of 32^3 windows at 50 % overlap (8 649 windows), no predictor: plain FFT PIV.
void BM_Correlate_512x512x160_32cubed_single_pass(benchmark::State& state) {
  tomorig::piv::CorrelationOptions options;
  tomorig::piv::CorrelationPass pass;
  pass.window = {32, 32, 32};
  pass.overlap = 0.5;
  options.passes.push_back(pass);
  options.threads = static_cast<int>(state.range(0));
  run(state, options);
}

void BM_Correlate_512x512x160_64x64x32(benchmark::State& state) { run(state, {64, 64, 32}); }
void BM_Correlate_512x512x160_48cubed(benchmark::State& state) { run(state, {48, 48, 48}); }
// The tpiv-thesis scheme at 0.05 ppp: 32^3 final windows hold ~10 particles.
void BM_Correlate_512x512x160_32cubed(benchmark::State& state) { run(state, {32, 32, 32}); }

BENCHMARK(BM_Correlate_512x512x160_64x64x32)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_Correlate_512x512x160_48cubed)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_Correlate_512x512x160_32cubed)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_Correlate_512x512x160_32cubed_single_pass)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace
