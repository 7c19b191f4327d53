// Simulator throughput on the tpiv-thesis case: one 512 x 512 image (project + render), the
// sensor model, and a whole set (4 cameras x 2 exposures). Arguments: ppp in thousandths.
#include <benchmark/benchmark.h>

#include "tomorig/simulators/simulated_rig.h"

namespace {

tomorig::sim::SimulationOptions options(benchmark::State& state) {
  tomorig::sim::SimulationOptions o;
  o.ppp = static_cast<double>(state.range(0)) / 1000.0;
  return o;
}

void BM_RenderImage(benchmark::State& state) {
  const tomorig::sim::SimulatedRig rig(options(state));
  const auto particles = rig.particle_midpoints(0);
  for (auto _ : state) benchmark::DoNotOptimize(rig.render_signal(0, particles));
  state.counters["particles"] = static_cast<double>(particles.size());
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(particles.size()));
}
BENCHMARK(BM_RenderImage)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond);

void BM_Digitise(benchmark::State& state) {
  const tomorig::sim::SimulatedRig rig(options(state));
  const tomorig::Image signal = rig.render_signal(0, rig.particle_midpoints(0));
  tomorig::sim::SensorOptions sensor;
  sensor.noise = true;
  for (auto _ : state) benchmark::DoNotOptimize(tomorig::sim::digitise(signal, sensor, 1));
}
BENCHMARK(BM_Digitise)->Arg(50)->Unit(benchmark::kMillisecond);

void BM_RenderSet(benchmark::State& state) {
  const tomorig::sim::SimulatedRig rig(options(state));
  std::uint64_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(rig.render_set(k++));
}
BENCHMARK(BM_RenderSet)->Arg(50)->Unit(benchmark::kMillisecond);

}  // namespace
