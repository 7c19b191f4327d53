#pragma once
// The command-line choices `tomorig run` and `tomorig acquire` share: which rig, how many sets,
// the pacing of a simulated trigger, what a lost camera does, injected faults and the status
// socket. One place registers them and turns them into RigAcquisitionOptions, so the two
// commands cannot drift apart in what they accept or how they refuse it.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/rig/rig_acquisition.h"

namespace CLI {
class App;
}

namespace tomorig::rig {

struct RigRunChoices {
  std::string config_path;  // empty: the embedded simulated rig
  std::optional<std::uint64_t> sets;
  std::optional<double> duration_s;
  std::string pace = "real-time";
  std::string on_camera_loss = "stop";
  std::vector<std::string> faults;  // CAMERA:vanish-after=EVENTS
  std::string status = "tcp://127.0.0.1:5556";
};

// Registers -c/--config, --sets, --duration, --pace, --on-camera-loss, --status and
// --inject-fault; `what` names the activity in the help ("Record", "Acquire").
void add_rig_run_options(CLI::App& cmd, RigRunChoices& choices, const std::string& what);

// The rig file, or the embedded rig. Throws as config::load_rig_config does.
config::RigConfig load_rig(const RigRunChoices& choices);

// Checks the choices (bad_input naming the option: --sets < 1, an unknown --pace or
// --on-camera-loss, a malformed --inject-fault, a --status that is not a loopback or ipc
// address) and fills the acquisition options. A simulated
// rig stops after its configured number of sets unless --sets or --duration says otherwise; a
// camera rig runs until Ctrl-C.
RigAcquisitionOptions rig_acquisition_options(const config::RigConfig& rig, const RigRunChoices& choices);

// "N sets", "S s" or "until Ctrl-C", for the start-of-run line.
std::string run_length_text(const RigAcquisitionOptions& options);

}  // namespace tomorig::rig
