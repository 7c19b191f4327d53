#include "tomorig/rig/rig_acquisition.h"

#include <charconv>
#include <exception>
#include <utility>

#include <fmt/core.h>

#include "tomorig/rig/simulate_session.h"
#include "tomorig/acquisition/aravis_camera.h"
#include "tomorig/core/error.h"
#include "tomorig/simulators/simulated_rig.h"
#include "tomorig/trigger/rig_trigger.h"
#include "tomorig/trigger/trigger_device.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;

// How often the loop looks up from waiting for an event to check for a stop or the duration.
constexpr std::chrono::milliseconds kEventPoll{50};

}  // namespace

std::optional<CameraLossPolicy> parse_camera_loss_policy(std::string_view text) {
  if (text == "stop") return CameraLossPolicy::stop;
  if (text == "continue") return CameraLossPolicy::continue_;
  return std::nullopt;
}

void add_camera_fault(std::map<std::string, acquisition::SimulatedCameraFaults>& faults, const std::string& text) {
  const auto colon = text.find(':');
  const std::string key = "vanish-after=";
  const std::string usage = "use CAMERA:vanish-after=EVENTS, e.g. cam1:vanish-after=10";
  if (colon == std::string::npos || colon == 0 || text.compare(colon + 1, key.size(), key) != 0)
    throw bad_input(fmt::format("--inject-fault '{}' is not understood: {}", text, usage));
  const std::string number = text.substr(colon + 1 + key.size());
  std::uint64_t events = 0;
  const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), events);
  if (number.empty() || ec != std::errc() || end != number.data() + number.size())
    throw bad_input(fmt::format("--inject-fault '{}': '{}' is not a number of events; {}", text, number, usage));
  faults[text.substr(0, colon)].vanish_after_events = events;
}

RigAcquisition::RigAcquisition(const config::RigConfig& rig, RigAcquisitionOptions options)
    : rig_(rig), options_(std::move(options)) {
  if (rig_.cameras.empty()) throw bad_input("the rig has no cameras; add a [[cameras]] entry");
  if (options_.sets && *options_.sets < 1)
    throw bad_input(fmt::format("--sets {} is invalid: must be >= 1", *options_.sets));
  if (options_.duration_s && !(*options_.duration_s > 0.0))
    throw bad_input(fmt::format("--duration {:g} is invalid: it must be > 0 seconds", *options_.duration_s));

  std::size_t simulated = 0;
  for (const auto& cam : rig_.cameras) simulated += cam.backend == config::CameraBackend::simulated ? 1 : 0;
  if (simulated != 0 && simulated != rig_.cameras.size())
    throw bad_input("the rig mixes simulated and aravis cameras; use one backend for every camera");
  for (const auto& [id, fault] : options_.faults) {
    bool known = false;
    for (const auto& cam : rig_.cameras) known |= cam.id == id && cam.backend == config::CameraBackend::simulated;
    if (!known)
      throw bad_input(fmt::format("--inject-fault names camera '{}', which is not a simulated camera of the rig", id));
  }

  // The trigger timing and the light sources' safety limits are checked before anything runs;
  // arm() checks them again on the device's own table.
  const trigger::RigTrigger rig_trigger = trigger::rig_trigger(rig_);
  const trigger::TimingPlan plan = trigger::plan_and_check(rig_trigger);
  device_ = trigger::make_trigger_device(rig_trigger, options_.pacing);
  device_->arm(plan);

  acquisition::AssemblerOptions assembly;
  for (const auto& cam : rig_.cameras) assembly.camera_ids.push_back(cam.id);
  assembly.timeout = options_.set_timeout;
  assembler_ = std::make_unique<acquisition::FrameSetAssembler>(assembly);
  camera_ids_ = assembly.camera_ids;
  reported_lost_.assign(camera_ids_.size(), false);

  if (simulated != 0) {
    if (!rig_.simulation)
      throw bad_input("the rig has simulated cameras but no [simulation] table; add one (see 'tomorig config default')");
    simulator_ = std::make_unique<sim::SimulatedRig>(simulation_options_from(rig_));
    for (const auto& cam : simulator_->cameras())
      session_cameras_.push_back(
          {cam.spec.id, cam.spec.width, cam.spec.height, cam.spec.pixel_format, cam.spec.pixel_pitch_um});
    for (const auto& cam : rig_.cameras) {
      const auto fault = options_.faults.find(cam.id);
      auto camera = std::make_unique<acquisition::SimulatedCamera>(
          cam.id,
          [this](const std::string& id, const acquisition::TriggerInput&) {
            // Rendered once per event for all cameras by handle_event(); each camera takes its pair.
            auto it = rendered_.find(id);
            if (it == rendered_.end()) throw runtime_error(fmt::format("camera {}: no frames rendered", id));
            acquisition::RenderedPair pair = std::move(it->second);
            rendered_.erase(it);
            return pair;
          },
          fault == options_.faults.end() ? acquisition::SimulatedCameraFaults{} : fault->second);
      camera->configure(cam);
      simulated_cameras_.push_back(camera.get());
      cameras_.push_back(std::move(camera));
    }
  } else {
    // With a simulated trigger device nothing fires the cameras' trigger lines, so the loop
    // sends software triggers; a hardware trigger device drives the lines itself.
    software_triggers_ = rig_.trigger.backend == config::TriggerBackend::simulated;
    for (const auto& cam : rig_.cameras) {
      acquisition::AravisCameraOptions aravis;
      if (software_triggers_) aravis.trigger_source = "Software";
      auto camera = std::make_unique<acquisition::AravisCamera>(cam.id, aravis);
      camera->configure(cam);  // an absent camera or a refused feature is named here
      session_cameras_.push_back({cam.id, cam.roi.width, cam.roi.height, cam.pixel_format, cam.pixel_pitch_um});
      cameras_.push_back(std::move(camera));
    }
  }
}

RigAcquisition::~RigAcquisition() {
  request_stop();
  // The worker may be waiting for room in the assembler's queue: drain until it has finished.
  while (worker_.joinable() && !finished_) assembler_->pop(std::chrono::milliseconds(20));
  if (worker_.joinable()) worker_.join();
  for (auto& camera : cameras_) camera->stop();
}

void RigAcquisition::start() {
  for (std::size_t c = 0; c < cameras_.size(); ++c)
    cameras_[c]->start([this, c](acquisition::CameraFrame&& frame) { assembler_->add_frame(c, std::move(frame)); });
  device_->start(options_.sets);
  worker_ = std::thread([this] { loop(); });
}

void RigAcquisition::request_stop() { stop_requested_ = true; }

void RigAcquisition::loop() {
  const auto started = Clock::now();
  try {
    for (;;) {
      if (stop_requested_) break;
      if (options_.duration_s &&
          std::chrono::duration<double>(Clock::now() - started).count() >= *options_.duration_s)
        break;
      if (options_.sets && events_handled_ + device_->dropped_events() >= *options_.sets) break;
      const auto event = device_->next_event_for(kEventPoll);
      if (!event) continue;
      handle_event(event->index, event->pulse1_ns, event->dt_ns);
      ++events_handled_;
    }
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    failure_ = fmt::format("acquisition failed: {}", e.what());
  }
  finish_run();
}

void RigAcquisition::handle_event(std::uint64_t index, std::int64_t timestamp_ns, std::int64_t dt_ns) {
  const acquisition::TriggerInput input{index, timestamp_ns, dt_ns};
  if (simulator_) {
    // Rendering is the simulated cameras' exposure and readout: the set's timeout starts when
    // they deliver, not before (a slow machine would otherwise time every set out).
    sim::SimulatedSet set = simulator_->render_set(index, dt_ns);
    assembler_->add_trigger(input);
    for (auto& frames : set.frames.cameras)
      rendered_[frames.camera_id] = {std::move(frames.a.image), std::move(frames.b.image)};
    if (options_.keep_truth) {
      std::lock_guard lock(mutex_);
      truth_[index] = {std::move(set.particles_a), std::move(set.particles_b)};
    }
    for (auto* camera : simulated_cameras_) camera->trigger(input);
    rendered_.clear();  // frames of a camera that has vanished
  } else {
    assembler_->add_trigger(input);
    if (software_triggers_)  // otherwise the trigger device's lines fire the cameras
      for (auto& camera : cameras_) {
        auto& aravis = static_cast<acquisition::AravisCamera&>(*camera);
        for (int k = 0; k < aravis.triggers_per_set(); ++k) aravis.software_trigger();
      }
  }
  check_cameras(index);
}

void RigAcquisition::check_cameras(std::uint64_t index) {
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    if (reported_lost_[c] || cameras_[c]->connected()) continue;
    reported_lost_[c] = true;
    if (options_.on_camera_loss == CameraLossPolicy::stop) {
      const std::string why = fmt::format("camera {} vanished at trigger {}; stopping the run (--on-camera-loss stop)",
                                          camera_ids_[c], index);
      notice(why);
      std::lock_guard lock(mutex_);
      if (failure_.empty()) failure_ = why;
      stop_requested_ = true;
    } else {
      notice(fmt::format("camera {} vanished at trigger {}; continuing without it (--on-camera-loss continue), "
                         "its frames are recorded as missing",
                         camera_ids_[c], index));
    }
  }
}

void RigAcquisition::finish_run() {
  device_->stop();
  for (auto& camera : cameras_) camera->stop();
  assembler_->flush();
  finished_ = true;
}

void RigAcquisition::notice(std::string text) {
  std::lock_guard lock(mutex_);
  notices_.push_back(std::move(text));
}

std::optional<FrameSet> RigAcquisition::pop(std::chrono::milliseconds wait) {
  if (done()) return std::nullopt;
  return assembler_->pop(wait);
}

bool RigAcquisition::done() const { return finished_ && assembler_->queued() == 0; }

std::string RigAcquisition::failure() const {
  std::lock_guard lock(mutex_);
  return failure_;
}

std::vector<std::string> RigAcquisition::take_notices() {
  std::lock_guard lock(mutex_);
  return std::exchange(notices_, {});
}

RigProgress RigAcquisition::progress() const {
  RigProgress p;
  p.trigger_events = events_handled_;
  p.dropped_trigger_events = device_->dropped_events();
  p.queued_sets = assembler_->queued();
  p.assembly = assembler_->statistics();
  for (std::size_t c = 0; c < cameras_.size(); ++c)
    p.cameras.push_back({camera_ids_[c], cameras_[c]->connected(), cameras_[c]->statistics()});
  return p;
}

std::optional<storage::SessionTruth> RigAcquisition::session_truth() const {
  if (!simulator_ || !options_.keep_truth) return std::nullopt;
  storage::SessionTruth truth;
  truth.case_name = simulator_->case_definition().name;
  truth.flow_name = simulator_->flow().name();
  truth.flow_parameters = simulator_->flow().parameters_json();
  truth.seed = simulator_->options().seed;
  truth.ppp = simulator_->options().ppp;
  for (const auto& cam : simulator_->cameras()) truth.cameras.push_back(truth_camera_of(cam));
  return truth;
}

std::optional<storage::TruthSet> RigAcquisition::take_truth(std::uint64_t trigger_index) {
  std::lock_guard lock(mutex_);
  const auto it = truth_.find(trigger_index);
  if (it == truth_.end()) return std::nullopt;
  storage::TruthSet truth = std::move(it->second);
  truth_.erase(it);
  return truth;
}

}  // namespace tomorig::rig
