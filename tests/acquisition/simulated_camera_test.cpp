#include "tomorig/acquisition/simulated_camera.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "tomorig/acquisition/frame_set_assembler.h"
#include "tomorig/core/error.h"
#include "tomorig/simulators/simulated_rig.h"

namespace tomorig::acquisition {
namespace {

sim::SimulationOptions small_rig() {
  sim::SimulationOptions opt;
  opt.ppp = 0.02;
  opt.seed = 11;
  for (int c = 0; c < 2; ++c) {
    sim::SimulatedCameraSpec spec;
    spec.id = "cam" + std::to_string(c);
    spec.yaw_deg = c == 0 ? -20.0 : 20.0;
    spec.width = 96;
    spec.height = 64;
    opt.cameras.push_back(spec);
  }
  return opt;
}

config::CameraConfig simulated_config(const std::string& id) {
  config::CameraConfig cfg;
  cfg.id = id;
  cfg.backend = config::CameraBackend::simulated;
  cfg.device_id = id;
  cfg.roi.width = 96;
  cfg.roi.height = 64;
  return cfg;
}

// Renders each trigger's set once, whichever camera asks first, and hands every camera its
// own pair (the way the apps layer plugs the simulator in).
class RigRenderer {
 public:
  explicit RigRenderer(const sim::SimulationOptions& opt) : rig_(opt) {}
  RenderedPair operator()(const std::string& camera_id, const TriggerInput& event) {
    std::lock_guard lock(mutex_);
    auto found = cache_.find(event.index);
    if (found == cache_.end()) found = cache_.emplace(event.index, rig_.render_set(event.index).frames).first;
    for (const auto& c : found->second.cameras)
      if (c.camera_id == camera_id) return {c.a.image, c.b.image};
    throw std::logic_error("no camera " + camera_id);
  }

 private:
  sim::SimulatedRig rig_;
  std::mutex mutex_;
  std::map<std::uint64_t, FrameSet> cache_;
};

TEST(SimulatedCamera, DeliversRenderedPairsThatAssembleIntoTheSimulatorsSets) {
  auto renderer = std::make_shared<RigRenderer>(small_rig());
  auto render = [renderer](const std::string& id, const TriggerInput& e) { return (*renderer)(id, e); };
  std::vector<std::unique_ptr<SimulatedCamera>> cameras;
  AssemblerOptions ao;
  for (int c = 0; c < 2; ++c) {
    ao.camera_ids.push_back("cam" + std::to_string(c));
    cameras.push_back(std::make_unique<SimulatedCamera>(ao.camera_ids.back(), render));
    cameras.back()->configure(simulated_config(ao.camera_ids.back()));
  }
  std::int64_t now = 0;
  FrameSetAssembler assembler(ao, [&] { return now; });
  for (std::size_t c = 0; c < cameras.size(); ++c)
    cameras[c]->start([&assembler, c](CameraFrame&& f) { assembler.add_frame(c, std::move(f)); });

  // Events with a jittered Δt: the set must carry each event's own Δt and timestamps.
  const std::vector<TriggerInput> events = {{0, 1'000'000, 100'000}, {1, 101'000'000, 100'013}, {2, 201'000'000, 99'991}};
  for (const auto& e : events)
    for (auto& cam : cameras) cam->trigger(e);

  const sim::SimulatedRig truth_rig(small_rig());  // independent rendering: the ground truth
  for (const auto& e : events) {
    auto set = assembler.try_pop();
    ASSERT_TRUE(set);
    EXPECT_EQ(set->trigger_index, e.index);
    EXPECT_EQ(set->trigger_timestamp_ns, e.timestamp_ns);
    EXPECT_EQ(set->dt_ns, e.dt_ns);
    ASSERT_TRUE(set->complete());
    const FrameSet truth = truth_rig.render_set(e.index).frames;
    for (std::size_t c = 0; c < 2; ++c) {
      EXPECT_EQ(set->cameras[c].a.timestamp_ns, e.timestamp_ns);
      EXPECT_EQ(set->cameras[c].b.timestamp_ns, e.timestamp_ns + e.dt_ns);
      EXPECT_TRUE(set->cameras[c].a.image.same_pixels(truth.cameras[c].a.image)) << "set " << e.index << " cam " << c;
      EXPECT_TRUE(set->cameras[c].b.image.same_pixels(truth.cameras[c].b.image)) << "set " << e.index << " cam " << c;
    }
  }
  for (auto& cam : cameras) {
    cam->stop();
    EXPECT_EQ(cam->statistics().delivered, 6u);
  }
}

TEST(SimulatedCamera, TriggerWhileStoppedIsCountedNotDelivered) {
  int calls = 0;
  SimulatedCamera cam("cam0", [&](const std::string&, const TriggerInput&) {
    ++calls;
    return RenderedPair{Image::allocate(96, 64, SampleType::u16), Image::allocate(96, 64, SampleType::u16)};
  });
  cam.configure(simulated_config("cam0"));
  int delivered = 0;
  cam.start([&](CameraFrame&&) { ++delivered; });
  cam.trigger({0, 0, 1000});
  cam.stop();
  cam.trigger({1, 0, 1000});
  EXPECT_EQ(delivered, 2);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(cam.statistics().underruns, 1u);
}

TEST(SimulatedCamera, RejectsWrongBackendWrongSizeAndStartBeforeConfigure) {
  auto render = [](const std::string&, const TriggerInput&) {
    return RenderedPair{Image::allocate(10, 10, SampleType::u16), Image::allocate(10, 10, SampleType::u16)};
  };
  SimulatedCamera cam("cam0", render);
  EXPECT_THROW(cam.start([](CameraFrame&&) {}), Error);
  config::CameraConfig cfg = simulated_config("cam0");
  cfg.backend = config::CameraBackend::aravis;
  try {
    cam.configure(cfg);
    FAIL() << "an aravis camera config was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("cam0"), std::string::npos);
  }
  cam.configure(simulated_config("cam0"));
  cam.start([](CameraFrame&&) {});
  try {
    cam.trigger({0, 0, 1});
    FAIL() << "a 10 x 10 frame was accepted for a 96 x 64 ROI";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("96 x 64"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SimulatedCamera("", render), Error);
  EXPECT_THROW(SimulatedCamera("x", nullptr), Error);
}

TEST(SimulatedCamera, InjectedVanishStopsDeliveryAndTheAssemblerCountsTheLoss) {
  auto render = [](const std::string&, const TriggerInput&) {
    return RenderedPair{Image::allocate(96, 64, SampleType::u16), Image::allocate(96, 64, SampleType::u16)};
  };
  AssemblerOptions ao;
  ao.camera_ids = {"cam0", "cam1"};
  ao.timeout = std::chrono::milliseconds(10);
  std::int64_t now = 0;
  FrameSetAssembler assembler(ao, [&] { return now; });
  SimulatedCamera healthy("cam0", render);
  SimulatedCameraFaults faults;
  faults.vanish_after_events = 2;
  SimulatedCamera failing("cam1", render, faults);
  SimulatedCamera* cams[2] = {&healthy, &failing};
  for (std::size_t c = 0; c < 2; ++c) {
    cams[c]->configure(simulated_config(ao.camera_ids[c]));
    cams[c]->start([&assembler, c](CameraFrame&& f) { assembler.add_frame(c, std::move(f)); });
  }
  for (std::uint64_t k = 0; k < 4; ++k) {
    assembler.add_trigger({k, static_cast<std::int64_t>(k) * 1000, 100});
    for (auto* cam : cams) cam->trigger({k, static_cast<std::int64_t>(k) * 1000, 100});
    EXPECT_EQ(failing.connected(), k < 2) << "after event " << k;
  }
  EXPECT_TRUE(healthy.connected());
  EXPECT_EQ(failing.statistics().delivered, 4u);  // 2 events x (A, B)
  now += 20'000'000;  // past the timeout: the sets missing cam1 leave flagged
  for (std::uint64_t k = 0; k < 4; ++k) {
    auto set = assembler.try_pop();
    ASSERT_TRUE(set) << "set " << k;
    EXPECT_EQ(set->complete(), k < 2) << "set " << k;
    EXPECT_EQ(set->cameras[1].a.present(), k < 2);
    EXPECT_TRUE(set->cameras[0].b.present());
  }
  const AssemblyStatistics stats = assembler.statistics();
  EXPECT_EQ(stats.sets_incomplete, 2u);
  EXPECT_EQ(stats.cameras[1].frames_missing, 4u);
  EXPECT_EQ(stats.cameras[0].frames_missing, 0u);
}

// SimulatedRig::render_set(k, dt): a live event's actual Δt moves the particles accordingly.
TEST(SimulatedRigDt, NominalDtIsBitIdenticalAndAnotherDtScalesTheDisplacement) {
  const sim::SimulatedRig rig(small_rig());
  const std::int64_t nominal = rig.options().dt_ns;
  const sim::SimulatedSet a = rig.render_set(3);
  const sim::SimulatedSet b = rig.render_set(3, nominal);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_TRUE(a.frames.cameras[c].b.image.same_pixels(b.frames.cameras[c].b.image));
    EXPECT_TRUE(a.frames.cameras[c].a.image.same_pixels(b.frames.cameras[c].a.image));
  }
  const sim::SimulatedSet longer = rig.render_set(3, nominal * 3 / 2);
  EXPECT_EQ(longer.frames.dt_ns, nominal * 3 / 2);
  ASSERT_EQ(longer.particles_a.size(), a.particles_a.size());
  double moved = 0;
  for (std::size_t n = 0; n < a.particles_a.size(); ++n) {
    const Vec3d d0 = a.particles_b[n] - a.particles_a[n];
    const Vec3d d1 = longer.particles_b[n] - longer.particles_a[n];
    const Vec3d mid0 = (a.particles_a[n] + a.particles_b[n]) * 0.5;
    const Vec3d mid1 = (longer.particles_a[n] + longer.particles_b[n]) * 0.5;
    EXPECT_NEAR(d1.x, 1.5 * d0.x, 1e-12);
    EXPECT_NEAR(d1.y, 1.5 * d0.y, 1e-12);
    EXPECT_NEAR(d1.z, 1.5 * d0.z, 1e-12);
    EXPECT_NEAR(mid1.x, mid0.x, 1e-12);
    moved += std::abs(d0.x) + std::abs(d0.y) + std::abs(d0.z);
  }
  EXPECT_GT(moved, 0.0);  // the flow does move the particles, so the check above means something
  // Frame B differs (the particles moved further); frame A differs too (central straddling).
  EXPECT_FALSE(longer.frames.cameras[0].b.image.same_pixels(a.frames.cameras[0].b.image));
  EXPECT_THROW(rig.render_set(3, -1), Error);
}

}  // namespace
}  // namespace tomorig::acquisition
