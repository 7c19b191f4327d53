// Reconstruction on the full tpiv-thesis case (512 x 512 x 160 voxels, 4 cameras of 512 x 512,
// noise-free, seed 1, set 0): MLOS, FMART and SMART, each timed end to end for a given number
// of iterations. Counters: Q against the truth (Gaussian blobs of diameter 3 voxel at the true
// positions, Eq. 3.14), the set-up time (input checks + projection set-up + MLOS + sparse
// system), the mean time of one iteration, active voxels and peak RSS.
//   recon_benchmark --benchmark_format=json          (threads: OMP_NUM_THREADS, default all)
// Arguments: ppp in thousandths, iterations, MLOS threshold in % of each image's maximum,
// weight sigma in hundredths of a pixel.
#include <cmath>
#include <map>
#include <memory>

#include <benchmark/benchmark.h>

#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/simulators/simulated_rig.h"

namespace {

using namespace tomorig;

struct Case {
  std::unique_ptr<sim::SimulatedRig> rig;
  std::vector<Image> images;
  std::vector<Vec3d> particles;
  std::vector<float> truth;  // dense, grid order
  double truth_norm = 0;
  VoxelGrid grid;
};

const Case& thesis_case(int ppp_thousandths) {
  static std::map<int, Case> cache;
  auto [it, inserted] = cache.try_emplace(ppp_thousandths);
  Case& c = it->second;
  if (!inserted) return c;
  sim::SimulationOptions o;
  o.ppp = ppp_thousandths / 1000.0;
  c.rig = std::make_unique<sim::SimulatedRig>(o);
  c.grid = c.rig->case_definition().grid;
  c.particles = c.rig->particle_midpoints(0);
  for (std::size_t cam = 0; cam < c.rig->cameras().size(); ++cam) c.images.push_back(c.rig->render_signal(cam, c.particles));
  c.truth.assign(c.grid.voxel_count(), 0.0f);
  for (const Vec3d& p : c.particles) {
    const Vec3d q = c.grid.voxel_of(p);
    const int ci = static_cast<int>(std::lround(q.x)), cj = static_cast<int>(std::lround(q.y)),
              ck = static_cast<int>(std::lround(q.z));
    for (int k = std::max(0, ck - 3); k <= std::min(c.grid.nz - 1, ck + 3); ++k)
      for (int j = std::max(0, cj - 3); j <= std::min(c.grid.ny - 1, cj + 3); ++j)
        for (int i = std::max(0, ci - 3); i <= std::min(c.grid.nx - 1, ci + 3); ++i) {
          const double d2 = (i - q.x) * (i - q.x) + (j - q.y) * (j - q.y) + (k - q.z) * (k - q.z);
          c.truth[c.grid.linear(i, j, k)] += static_cast<float>(std::exp(-d2 / (2 * 0.75 * 0.75)));
        }
  }
  for (float g : c.truth) c.truth_norm += static_cast<double>(g) * g;
  return c;
}

double quality(const SparseVolume& v, const Case& c) {
  double eg = 0, ee = 0;
  for (std::size_t n = 0; n < v.size(); ++n) {
    eg += static_cast<double>(v.intensity[n]) * c.truth[v.index[n]];
    ee += static_cast<double>(v.intensity[n]) * v.intensity[n];
  }
  return ee > 0 ? eg / std::sqrt(ee * c.truth_norm) : 0.0;
}

void run(benchmark::State& state, const char* algorithm) {
  const Case& c = thesis_case(static_cast<int>(state.range(0)));
  recon::ReconstructionInput input;
  input.grid = c.grid;
  input.images = c.images;
  for (const auto& cam : c.rig->cameras()) input.cameras.push_back(&cam.model);
  recon::ReconstructionOptions o;
  o.algorithm = algorithm;
  o.max_iterations = static_cast<int>(std::max<std::int64_t>(1, state.range(1)));
  o.mlos_threshold = static_cast<double>(state.range(2)) / 100.0;
  input.psf.assign(input.cameras.size(), recon::PsfModel::constant(static_cast<double>(state.range(3)) / 100.0));
  if (o.algorithm == "smart") o.relaxation = 1.5;
  auto reconstructor = recon::make_reconstructor(o);
  recon::ReconstructionReport report;
  SparseVolume v;
  double setup = 0, iteration = 0, iterations = 0;
  for (auto _ : state) {
    v = reconstructor->reconstruct(input, report);
    setup += report.setup_seconds;
    for (const auto& h : report.history) iteration += h.seconds;
    iterations += static_cast<double>(report.history.size());
  }
  state.counters["q"] = quality(v, c);
  state.counters["setup_s"] = setup / static_cast<double>(state.iterations());
  state.counters["iteration_s"] = iterations > 0 ? iteration / iterations : 0.0;
  state.counters["active_voxels"] = static_cast<double>(report.active_voxels);
  state.counters["peak_rss_mb"] = report.peak_rss_mb;
  state.counters["threads"] = report.threads;
}

void BM_Mlos(benchmark::State& state) { run(state, "mlos"); }
void BM_Fmart(benchmark::State& state) { run(state, "fmart"); }
void BM_Smart(benchmark::State& state) { run(state, "smart"); }

BENCHMARK(BM_Mlos)->Args({50, 0, 5, 50})->Args({50, 0, 15, 50})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Fmart)
    ->Args({50, 1, 5, 50})
    ->Args({50, 6, 5, 50})
    ->Args({50, 1, 15, 50})
    ->Args({50, 6, 15, 50})
    ->Args({50, 10, 15, 50})
    ->Args({50, 10, 15, 40})
    ->Args({50, 10, 25, 50})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Smart)->Args({50, 1, 15, 50})->Args({50, 10, 15, 50})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
