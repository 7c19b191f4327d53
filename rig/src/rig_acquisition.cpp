#include "tomorig/rig/rig_acquisition.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <limits>
#include <utility>

#include <fmt/core.h>

#include "tomorig/rig/buffer_memory.h"
#include "tomorig/rig/simulated_scene.h"
#include "tomorig/acquisition/aravis_camera.h"
#include "tomorig/acquisition/gentl_camera.h"
#include "tomorig/core/error.h"
#include "tomorig/trigger/rig_trigger.h"
#include "tomorig/trigger/trigger_device.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;

// How often the loop looks up from waiting for an event to check for a stop or the duration.
constexpr std::chrono::milliseconds kEventPoll{50};
// Camera buffer pools: besides the set timeout, the time a set may wait to be taken from the
// assembler and written, and a few buffers in flight in the stream itself.
constexpr std::chrono::duration<double> kQueueAllowance{0.5};
constexpr int kSpareBuffers = 8;

// How the assembler checks a camera's pairs: B - A of its timestamps against the plan's frame
// separation (Aravis cameras; a simulated camera stamps frames with the trigger's own times).
acquisition::AssemblerOptions::CameraPairing pairing_of(const config::CameraConfig& cam,
                                                        const config::CameraTimingConfig& timing,
                                                        const trigger::TimingPlan& plan) {
  acquisition::AssemblerOptions::CameraPairing pairing;
  if (cam.frame_mode == config::FrameMode::free_run) {
    pairing.free_running = true;
    return pairing;
  }
  if (cam.backend == config::CameraBackend::simulated) return pairing;
  pairing.expected_separation_ns = plan.frame_separation_ns();
  if (timing.frame_time_tolerance_us) {
    pairing.tolerance_ns = std::llround(*timing.frame_time_tolerance_us * 1000.0);
  } else if (cam.frame_mode == config::FrameMode::two_triggers) {
    // Half the distance to the nearest wrong pairing: B of the next event is a period minus
    // the separation away, frame A of this one the separation.
    pairing.tolerance_ns = std::min(pairing.expected_separation_ns, plan.period_ns - pairing.expected_separation_ns) / 2;
  }
  return pairing;
}

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
    throw bad_input("the rig mixes simulated and real (aravis, gentl) cameras; use simulated cameras for all or none");
  for (const auto& [id, fault] : options_.faults) {
    bool known = false;
    for (const auto& cam : rig_.cameras) known |= cam.id == id && cam.backend == config::CameraBackend::simulated;
    if (!known)
      throw bad_input(fmt::format("--inject-fault names camera '{}', which is not a simulated camera of the rig", id));
  }

  // The trigger timing and the light sources' safety limits are checked before anything runs;
  // arm() checks them again on the device's own table, after the cameras took the plan.
  const trigger::RigTrigger rig_trigger = trigger::rig_trigger(rig_);
  plan_ = trigger::plan_and_check(rig_trigger);

  acquisition::AssemblerOptions assembly;
  for (const auto& cam : rig_.cameras) assembly.camera_ids.push_back(cam.id);
  assembly.timeout = options_.set_timeout;
  // Never more sets than asked: frames of trigger indices past the run make none.
  if (options_.sets) assembly.end_trigger_index = *options_.sets;
  for (const auto& cam : rig_.cameras) assembly.pairing.push_back(pairing_of(cam, rig_.trigger.camera, plan_));
  assembler_ = std::make_unique<acquisition::FrameSetAssembler>(assembly);
  camera_ids_ = assembly.camera_ids;
  reported_lost_.assign(camera_ids_.size(), false);
  reported_mismatches_.assign(camera_ids_.size(), 0);
  for (const auto& cam : rig_.cameras) free_running_.push_back(cam.frame_mode == config::FrameMode::free_run);

  if (simulated != 0) {
    if (!rig_.simulation)
      throw bad_input("the rig has simulated cameras but no [simulation] table; add one (see 'tomorig config default')");
    simulator_ = make_simulated_scene(rig_);
    session_cameras_ = simulator_->cameras();
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
    // Frames wait in the assembler while a set waits for a late or lost frame (up to the set
    // timeout), and every camera's frames of the sets queued behind it wait too: the pool
    // must outlast that, or one camera's loss becomes every camera's underrun.
    const double set_timeout_s = std::chrono::duration<double>(options_.set_timeout).count();
    const int buffers = std::max(acquisition::AravisCameraOptions{}.buffer_count,
                                 static_cast<int>(std::ceil(2.0 * plan_.rate_hz * (set_timeout_s + kQueueAllowance.count()))) +
                                     kSpareBuffers);
    // The pools' memory is checked before any camera is opened when the rig file gives every
    // camera's size, else after configure() with the size the cameras report.
    std::vector<CameraBufferPool> pools;
    for (const auto& cam : rig_.cameras)
      if (cam.roi.width > 0 && cam.roi.height > 0)
        pools.push_back({cam.id, buffers,
                         static_cast<std::size_t>(cam.roi.width) * static_cast<std::size_t>(cam.roi.height) *
                             bytes_per_sample(sample_type_of(cam.pixel_format))});
    const bool sizes_known = pools.size() == rig_.cameras.size();
    if (sizes_known) check_buffer_memory(pools, plan_.rate_hz, set_timeout_s, memory_available_bytes());
    for (const auto& cam : rig_.cameras) {
      // The camera takes the plan: its frame mode, trigger source and the exposure.
      acquisition::AravisCameraOptions aravis;
      aravis.frame_mode = cam.frame_mode;
      if (software_triggers_) aravis.trigger_source = "Software";
      aravis.exposure_time_us = static_cast<double>(plan_.camera.exposure_a_ns) / 1000.0;
      aravis.buffer_count = buffers;
      if (software_triggers_) {
        // Frames answer triggers a period apart (hardware) or Δt and the rest of the period
        // apart (two_triggers): half the closer spacing tells them apart.
        const std::int64_t separation = plan_.frame_separation_ns();
        const std::int64_t closest = cam.frame_mode == config::FrameMode::two_triggers
                                         ? std::min(separation, plan_.period_ns - separation)
                                         : plan_.period_ns;
        aravis.match_tolerance_ns = closest / 2;
        if (cam.frame_mode == config::FrameMode::hardware) aravis.burst_separation_ns = separation;
        if (cam.frame_mode == config::FrameMode::two_triggers) aravis.readout_ns = plan_.camera.readout_ns;
      }
      // GenTL cameras (frame grabbers) are Aravis-engine cameras reached through a producer.
      auto camera = cam.backend == config::CameraBackend::gentl ? acquisition::make_gentl_camera(cam.id, aravis)
                                                                : std::make_unique<acquisition::AravisCamera>(cam.id, aravis);
      camera->configure(cam);  // an absent camera or a refused feature is named here
      session_cameras_.push_back({cam.id, cam.roi.width, cam.roi.height, cam.pixel_format, cam.pixel_pitch_um});
      aravis_cameras_.push_back(camera.get());
      cameras_.push_back(std::move(camera));
    }
    if (!sizes_known) {
      pools.clear();
      for (std::size_t c = 0; c < aravis_cameras_.size(); ++c)
        pools.push_back({camera_ids_[c], buffers, aravis_cameras_[c]->payload_bytes()});
      check_buffer_memory(pools, plan_.rate_hz, set_timeout_s, memory_available_bytes());
    }
  }

  // Armed last: a camera that cannot meet the plan is refused before any trigger line moves.
  device_ = trigger::make_trigger_device(rig_trigger, options_.pacing);
  device_->arm(plan_);
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
  warm_up_cameras();
  device_->start(options_.sets);
  worker_ = std::thread([this] { loop(); });
}

// Some cameras take their first trigger after AcquisitionStart late or not at all (Aravis's
// GigE fake looks for it only every 100 ms until it has sent a frame, so a second trigger
// 60 ms later is lost). One trigger before the run, whose frame is discarded, makes every
// software-triggered camera ready and gives its frame matcher a first frame to measure from.
void RigAcquisition::warm_up_cameras() {
  if (!software_triggers_) return;
  std::vector<std::size_t> warming;
  for (std::size_t c = 0; c < aravis_cameras_.size(); ++c) {
    if (free_running_[c]) continue;
    aravis_cameras_[c]->request_software_trigger(std::nullopt);
    warming.push_back(c);
  }
  const auto give_up = Clock::now() + std::chrono::seconds(1);
  for (const std::size_t c : warming)
    while (aravis_cameras_[c]->statistics().delivered == 0 && aravis_cameras_[c]->connected() && Clock::now() < give_up)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
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
      if (!event) {
        check_cameras(events_handled_);  // a camera lost between events is named within the poll time
        continue;
      }
      announce_dropped_events(event->index);
      handle_event(event->index, event->pulse1_ns, event->dt_ns);
      ++events_handled_;
    }
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    failure_ = fmt::format("acquisition failed: {}", e.what());
  }
  finish_run();
}

// A dropped event fired no camera (software triggers) or fired them unseen (trigger lines):
// its set still exists, with the event's real time and Δt, and is flagged by what is missing.
// Announced in index order, just before the next handled event, so a lagging loop does not
// start the timeouts of sets whose events it has not handled yet.
void RigAcquisition::announce_dropped_events(std::optional<std::uint64_t> before) {
  for (auto& e : device_->take_dropped_events()) dropped_.push_back(e);
  std::size_t announced = 0;
  for (const auto& e : dropped_) {
    if (before && e.index > *before) break;
    assembler_->add_trigger({e.index, e.pulse1_ns, e.dt_ns});
    ++announced;
  }
  dropped_.erase(dropped_.begin(), dropped_.begin() + static_cast<std::ptrdiff_t>(announced));
}

void RigAcquisition::handle_event(std::uint64_t index, std::int64_t timestamp_ns, std::int64_t dt_ns) {
  const acquisition::TriggerInput input{index, timestamp_ns, dt_ns};
  if (simulator_) {
    // Rendering is the simulated cameras' exposure and readout: the set's timeout starts when
    // they deliver, not before (a slow machine would otherwise time every set out).
    SceneSet set = simulator_->render(index, dt_ns);
    assembler_->add_trigger(input);
    for (auto& frames : set.frames.cameras)
      rendered_[frames.camera_id] = {std::move(frames.a.image), std::move(frames.b.image)};
    if (options_.keep_truth) {
      std::lock_guard lock(mutex_);
      truth_[index] = std::move(set.truth);
    }
    for (auto* camera : simulated_cameras_) camera->trigger(input);
    rendered_.clear();  // frames of a camera that has vanished
  } else {
    assembler_->add_trigger(input);
    trigger_aravis_cameras(index, dt_ns);
  }
  check_cameras(index);
  report_mismatches();
}

// Software triggers follow the plan: every camera is asked at once (each camera's own trigger
// thread sends the command, so one that stopped answering holds up nobody), and two-trigger
// cameras again when frame B starts, the plan's frame separation later (plus this event's Δt
// error). With a trigger device the lines fire the cameras; they are only told to expect frames.
void RigAcquisition::trigger_aravis_cameras(std::uint64_t index, std::int64_t dt_ns) {
  if (!software_triggers_) {
    for (std::size_t c = 0; c < aravis_cameras_.size(); ++c)
      if (!free_running_[c] && aravis_cameras_[c]->connected()) aravis_cameras_[c]->note_hardware_trigger();
    return;
  }
  // Frame B's trigger (two_triggers) follows A's by the plan's separation plus this event's
  // Δt error; each camera's trigger thread times it from when its A trigger really went out.
  const std::int64_t spacing = plan_.frame_separation_ns() + dt_ns - plan_.dt_ns;
  for (std::size_t c = 0; c < aravis_cameras_.size(); ++c)
    if (!free_running_[c] && aravis_cameras_[c]->connected()) aravis_cameras_[c]->request_software_trigger(index, spacing);
}

void RigAcquisition::report_mismatches() {
  const auto stats = assembler_->statistics();
  for (std::size_t c = 0; c < stats.cameras.size(); ++c) {
    const auto& cam = stats.cameras[c];
    if (cam.frames_mismatched == reported_mismatches_[c]) continue;
    // The first mismatch of a camera, then one line per 100 frames, so a steady fault does not
    // bury the status line.
    if (reported_mismatches_[c] == 0 || cam.frames_mismatched / 200 != reported_mismatches_[c] / 200)
      notice(fmt::format("{} ({} frames dropped so far)", cam.last_mismatch, cam.frames_mismatched));
    reported_mismatches_[c] = cam.frames_mismatched;
  }
}

void RigAcquisition::check_cameras(std::uint64_t index) {
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    if (reported_lost_[c] || cameras_[c]->connected()) continue;
    reported_lost_[c] = true;
    assembler_->mark_camera_lost(c);  // sets stop waiting for its frames
    const std::string problem = cameras_[c]->connection_problem();
    const std::string cause = problem.empty() ? std::string() : fmt::format(" ({})", problem);
    if (options_.on_camera_loss == CameraLossPolicy::stop) {
      const std::string why = fmt::format("camera {} vanished at trigger {}{}; stopping the run (--on-camera-loss stop)",
                                          camera_ids_[c], index, cause);
      notice(why);
      std::lock_guard lock(mutex_);
      if (failure_.empty()) failure_ = why;
      stop_requested_ = true;
    } else {
      notice(fmt::format("camera {} vanished at trigger {}{}; continuing without it (--on-camera-loss continue), "
                         "its frames are recorded as missing",
                         camera_ids_[c], index, cause));
    }
  }
}

void RigAcquisition::finish_run() {
  device_->stop();
  try {
    announce_dropped_events(std::nullopt);  // the run's last dropped events still get their sets
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    if (failure_.empty()) failure_ = fmt::format("acquisition failed: {}", e.what());
  }
  // Real cameras deliver the last event's frames after its trigger: give them the set timeout
  // to arrive before the streams close.
  if (!aravis_cameras_.empty()) {
    const auto give_up = Clock::now() + options_.set_timeout;
    while (assembler_->pending() > 0 && Clock::now() < give_up) {
      assembler_->expire();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
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
  p.trigger_queue = device_->queued_events();
  p.trigger_queue_capacity = device_->queue_capacity();
  p.rate_hz = plan_.rate_hz;
  p.queued_sets = assembler_->queued();
  p.assembly = assembler_->statistics();
  for (std::size_t c = 0; c < cameras_.size(); ++c)
    p.cameras.push_back({camera_ids_[c], cameras_[c]->connected(), cameras_[c]->connection_problem(),
                         free_running_[c], cameras_[c]->statistics()});
  return p;
}

std::optional<storage::SessionTruth> RigAcquisition::session_truth() const {
  if (!simulator_ || !options_.keep_truth) return std::nullopt;
  return simulator_->truth();
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
