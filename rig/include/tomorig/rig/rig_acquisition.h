#pragma once
// The acquisition half of a rig, shared by `tomorig run` (which records in the same process)
// and `tomorig acquire` (which streams to a recorder elsewhere):
//
//   trigger device (simulated or gpio) -> cameras -> FrameSetAssembler -> pop()
//
// Every trigger event is announced to the assembler (so a set whose frames never come still
// appears, flagged incomplete) and drives the cameras: a simulated camera renders the
// simulator's scene with the event's own Δt (jitter included, so a Δt error shows as a
// displacement error); an Aravis camera gets a software trigger when the trigger device is
// simulated, and is wired to the device's lines otherwise. One worker thread runs the loop; the
// caller pops sets from any one thread.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "tomorig/acquisition/camera.h"
#include "tomorig/acquisition/frame_set_assembler.h"
#include "tomorig/acquisition/simulated_camera.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/trigger/simulated_device.h"
#include "tomorig/trigger/timing_plan.h"

namespace tomorig::trigger {
class TriggerDevice;
struct TriggerEvent;
}
namespace tomorig::acquisition {
class AravisCamera;
}

namespace tomorig::rig {

class SimulatedScene;

// What to do when a camera vanishes mid-run.
enum class CameraLossPolicy : std::uint8_t {
  stop,      // stop the run; every set acquired so far is kept
  continue_, // go on without it: its frames are recorded as missing and counted
};
std::optional<CameraLossPolicy> parse_camera_loss_policy(std::string_view text);  // "stop" | "continue"

struct RigAcquisitionOptions {
  std::optional<std::uint64_t> sets;  // trigger events to fire; nullopt: until stop or duration
  std::optional<double> duration_s;   // stop after this many seconds
  trigger::Pacing pacing = trigger::Pacing::real_time;  // simulated trigger device only
  CameraLossPolicy on_camera_loss = CameraLossPolicy::stop;
  // Injected faults of simulated cameras, by camera id (tests and demonstrations).
  std::map<std::string, acquisition::SimulatedCameraFaults> faults;
  bool keep_truth = false;  // keep the simulator's particles of each set for take_truth()
  std::chrono::milliseconds set_timeout{500};  // FrameSetAssembler timeout
};

// Parses "<camera>:vanish-after=<events>" into `faults` (bad_input naming the problem).
void add_camera_fault(std::map<std::string, acquisition::SimulatedCameraFaults>& faults, const std::string& text);

struct CameraHealth {
  std::string id;
  bool connected = true;
  std::string problem;        // why it is not connected
  bool free_running = false;  // frame_mode "free_run": its sets are never complete
  acquisition::StreamStatistics stream;
};

// A snapshot for the status line and the status socket.
struct RigProgress {
  std::uint64_t trigger_events = 0;          // events the acquisition loop handled
  std::uint64_t dropped_trigger_events = 0;  // events a paced device fired while the loop lagged
  // Events fired and not yet handled: the loop's lag behind the trigger. A paced device drops
  // events once this reaches trigger_queue_capacity.
  std::size_t trigger_queue = 0;
  std::size_t trigger_queue_capacity = 0;
  double rate_hz = 0.0;                      // the trigger's event rate (lag in time = queue / rate)
  std::size_t queued_sets = 0;               // sets assembled and not yet popped
  acquisition::AssemblyStatistics assembly;
  std::vector<CameraHealth> cameras;
};

class RigAcquisition {
 public:
  // Builds and configures everything and arms the trigger device, so a bad rig (safety limit,
  // feature, absent camera) fails here, before any file exists. Throws tomorig::Error.
  RigAcquisition(const config::RigConfig& rig, RigAcquisitionOptions options);
  // Stops the run and discards sets nobody popped.
  ~RigAcquisition();
  RigAcquisition(const RigAcquisition&) = delete;
  RigAcquisition& operator=(const RigAcquisition&) = delete;

  void start();
  // Ends the run after the current event; pending sets are flushed (flagged if incomplete).
  // Thread-safe, idempotent.
  void request_stop();

  // The next set, or nullopt after `wait` (or when done()).
  std::optional<FrameSet> pop(std::chrono::milliseconds wait);
  // The run is over and every set has been popped.
  bool done() const;
  // Why the run ended early on its own (a camera lost under the stop policy, a device error);
  // empty otherwise.
  std::string failure() const;
  // Messages for the operator since the last call (a camera vanished, ...).
  std::vector<std::string> take_notices();

  RigProgress progress() const;
  const std::vector<std::string>& camera_ids() const { return camera_ids_; }
  // The session's cameras; a camera whose image size the configuration does not fix (an
  // Aravis camera without an ROI) has width and height 0.
  const std::vector<storage::SessionCamera>& session_cameras() const { return session_cameras_; }
  // Ground truth (simulated rigs with keep_truth only).
  std::optional<storage::SessionTruth> session_truth() const;
  // The particles of trigger event `index`, once (nullopt if unknown or already taken).
  std::optional<storage::TruthSet> take_truth(std::uint64_t trigger_index);

 private:
  void loop();
  void handle_event(std::uint64_t index, std::int64_t timestamp_ns, std::int64_t dt_ns);
  void trigger_aravis_cameras(std::uint64_t index, std::int64_t dt_ns);
  void announce_dropped_events(std::optional<std::uint64_t> before);
  void check_cameras(std::uint64_t index);
  void report_mismatches();
  void finish_run();
  void notice(std::string text);
  void warm_up_cameras();

  config::RigConfig rig_;
  RigAcquisitionOptions options_;
  std::vector<std::string> camera_ids_;
  std::vector<storage::SessionCamera> session_cameras_;
  std::unique_ptr<SimulatedScene> simulator_;  // the simulated cameras' scene (simulated_scene.h)
  std::unique_ptr<trigger::TriggerDevice> device_;
  std::unique_ptr<acquisition::FrameSetAssembler> assembler_;
  std::vector<std::unique_ptr<acquisition::Camera>> cameras_;
  std::vector<acquisition::SimulatedCamera*> simulated_cameras_;  // views into cameras_
  std::vector<acquisition::AravisCamera*> aravis_cameras_;        // views into cameras_
  std::vector<bool> free_running_;  // by camera: frame_mode "free_run"
  bool software_triggers_ = false;  // Aravis cameras triggered by the loop
  trigger::TimingPlan plan_;
  std::vector<bool> reported_lost_;
  std::vector<std::uint64_t> reported_mismatches_;
  // Dropped trigger events not yet announced to the assembler, oldest first.
  std::vector<trigger::TriggerEvent> dropped_;



  // The frames the simulator rendered for the event being handled, by camera id; the simulated
  // cameras' renderers take them from here (same thread).
  std::map<std::string, acquisition::RenderedPair> rendered_;

  mutable std::mutex mutex_;  // guards the members below
  std::map<std::uint64_t, storage::TruthSet> truth_;
  std::vector<std::string> notices_;
  std::string failure_;

  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> finished_{false};
  std::atomic<std::uint64_t> events_handled_{0};
  std::thread worker_;
};

}  // namespace tomorig::rig
