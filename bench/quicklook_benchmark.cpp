// Quick-look cost per camera frame at the issue 16 acceptance size: 2048 x 2048 Mono16,
// 0.05 ppp, d_tau 3 px, shot + read noise, 100 counts black level (rendered once by the
// simulator). QuickLookFrame: the statistics of one exposure (both passes). QuickLookCamera:
// a double frame with the energy balance. DtCheck: the 4 x 4 windows of 64 px of one camera.
// Run on a quiet machine:  build/bench/quicklook_benchmark --benchmark_counters_tabular=true
// The Time column is ms per frame, double frame or camera.
#include <random>

#include <benchmark/benchmark.h>

#include "tomorig/processing/quicklook/dt_check.h"
#include "tomorig/processing/quicklook/statistics.h"
#include "tomorig/simulators/particle_renderer.h"
#include "tomorig/simulators/sensor.h"

namespace {

constexpr int kSize = 2048;

struct Frames {
  tomorig::Image a, b;
};

const Frames& frames() {
  static const Frames f = [] {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-0.5, kSize - 0.5);
    std::vector<tomorig::sim::ParticleImage> particles(static_cast<std::size_t>(0.05 * kSize * kSize));
    for (auto& p : particles) p = {{u(rng), u(rng)}, 1000.0};
    tomorig::sim::ParticleImageOptions image;
    tomorig::sim::SensorOptions sensor;
    sensor.noise = true;
    sensor.offset_counts = 100;
    Frames out;
    for (tomorig::Image* frame : {&out.a, &out.b}) {
      tomorig::Image signal = tomorig::Image::allocate(kSize, kSize, tomorig::SampleType::f32);
      tomorig::sim::render_particle_images(particles, image, signal);
      *frame = tomorig::sim::digitise(signal, sensor, frame == &out.a ? 1 : 2);
      for (auto& p : particles) p.centre.x += 6.0;  // B: 6 px further
    }
    return out;
  }();
  return f;
}

void BM_QuickLookFrame(benchmark::State& state) {
  const Frames& f = frames();
  tomorig::quicklook::QuickLook ql;
  tomorig::quicklook::FrameStatistics s;
  for (auto _ : state) {
    ql.analyse(f.a, s);
    benchmark::DoNotOptimize(&s);
    benchmark::ClobberMemory();
  }
  // What was measured, to see the frame is a fair one (the time is the benchmark's own column).
  state.counters["ppp"] = s.ppp.value;
  state.counters["d_tau_px"] = s.diameter_px.value;
}

void BM_QuickLookCamera(benchmark::State& state) {
  const Frames& f = frames();
  tomorig::quicklook::QuickLook ql;
  tomorig::quicklook::CameraQuickLook s;
  for (auto _ : state) {
    ql.analyse(f.a, f.b, s);
    benchmark::DoNotOptimize(&s);
    benchmark::ClobberMemory();
  }
  state.counters["energy_balance"] = s.energy_balance.value;
}

void BM_DtCheck(benchmark::State& state) {
  const Frames& f = frames();
  tomorig::quicklook::DtCheck check;
  tomorig::quicklook::DtCheckResult r;
  for (auto _ : state) {
    check.check(f.a, f.b, r);
    benchmark::DoNotOptimize(&r);
    benchmark::ClobberMemory();
  }
  state.counters["displacement_px"] = r.displacement_px.value;
  state.counters["valid_fraction"] = r.valid_fraction.value;
}

}  // namespace

BENCHMARK(BM_QuickLookFrame)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_QuickLookCamera)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DtCheck)->Unit(benchmark::kMillisecond)->UseRealTime();
