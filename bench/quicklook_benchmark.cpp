// Quick-look cost per camera frame at the issue 16 acceptance size: 2048 x 2048 Mono16,
// 0.05 ppp, d_tau 3 px, shot + read noise, 100 counts black level (rendered once by the
// simulator). QuickLookFrame: the statistics of one exposure (both passes). QuickLookCamera:
// a double frame with the energy balance. DtCheck: the 4 x 4 windows of 64 px of one camera.
// PreviewVolume: the MLOS preview of one exposure of the tpiv-thesis rig (4 x 512^2, 0.05 ppp:
// binning, reconstruction on one thread, projections, depth profile), issue 16 item 3.
// What the quicklook stage adds per camera and set besides the statistics and the Δt check:
// Thumbnail (frame A shrunk to the stream's 160 px picture) and StatisticsJson (the camera's
// figures and maps as the JSON of the preview stream).
// Run on a quiet machine:  build/bench/quicklook_benchmark --benchmark_counters_tabular=true
// The Time column is ms per frame, double frame or camera.
#include <random>

#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>

#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/quicklook/display.h"
#include "tomorig/processing/quicklook/dt_check.h"
#include "tomorig/processing/quicklook/json.h"
#include "tomorig/processing/quicklook/preview_volume.h"
#include "tomorig/processing/quicklook/statistics.h"
#include "tomorig/simulators/particle_renderer.h"
#include "tomorig/simulators/sensor.h"
#include "tomorig/simulators/simulated_rig.h"

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

void BM_Thumbnail(benchmark::State& state) {
  const Frames& f = frames();
  for (auto _ : state) {
    tomorig::Image t = tomorig::quicklook::thumbnail(f.a, 160);
    benchmark::DoNotOptimize(t.data());
  }
}

void BM_StatisticsJson(benchmark::State& state) {
  const Frames& f = frames();
  tomorig::quicklook::QuickLook ql;
  tomorig::quicklook::CameraQuickLook s;
  ql.analyse(f.a, f.b, s);
  std::size_t bytes = 0;
  for (auto _ : state) {
    const nlohmann::json j = s;
    bytes = j.dump().size();
  }
  state.counters["bytes"] = static_cast<double>(bytes);
}

}  // namespace

void BM_PreviewVolume(benchmark::State& state) {
  const tomorig::sim::SimulatedRig rig(tomorig::sim::SimulationOptions{});
  std::vector<std::shared_ptr<const tomorig::calibration::CameraModel>> models;
  std::vector<tomorig::calibration::ImageSize> sizes;
  std::vector<tomorig::Image> images;
  const tomorig::sim::SimulatedSet set = rig.render_set(0);
  for (std::size_t c = 0; c < rig.cameras().size(); ++c) {
    models.push_back(std::make_shared<tomorig::calibration::PinholeCamera>(rig.cameras()[c].model));
    sizes.push_back({rig.cameras()[c].spec.width, rig.cameras()[c].spec.height});
    images.push_back(set.frames.cameras[c].a.image);
  }
  tomorig::quicklook::PreviewVolume preview(models, sizes, rig.case_definition().grid);
  tomorig::quicklook::PreviewResult result;
  for (auto _ : state) preview.reconstruct(images, result);
  state.counters["active_voxels"] = static_cast<double>(result.active_voxels);
  state.counters["thickness_mm"] = result.sheet.thickness_mm;
}

BENCHMARK(BM_QuickLookFrame)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_QuickLookCamera)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DtCheck)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Thumbnail)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StatisticsJson)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PreviewVolume)->Unit(benchmark::kMillisecond)->UseRealTime();
