#include "tomorig/rig/rig_run_options.h"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/stream/endpoint.h"

namespace tomorig::rig {
namespace {

trigger::Pacing parse_pace(const std::string& text) {
  if (text == "real-time") return trigger::Pacing::real_time;
  if (text == "max") return trigger::Pacing::as_fast_as_consumed;
  throw bad_input(fmt::format("--pace {} is not supported: use real-time or max", text));
}

// The status socket binds --status. Checked with the other options, before a file is created or
// a device armed, with advice for the command line: unlike the frame stream, the status
// socket has no way to allow a remote bind.
void check_status_endpoint(const std::string& address) {
  if (address.empty() || address == "none") return;
  try {
    stream::check_address_form(address);
  } catch (const Error& e) {
    throw bad_input(fmt::format("--status: {}", e.what()));
  }
  if (!stream::is_local_address(address))
    throw bad_input(fmt::format("--status {} would publish the rig's status to other hosts; bind it to loopback "
                                "(e.g. --status tcp://127.0.0.1:5556) or an ipc:// path, or pass --status none "
                                "(a remote monitor connects through an SSH tunnel to the loopback port)",
                                address));
}

}  // namespace

void add_rig_run_options(CLI::App& cmd, RigRunChoices& choices, const std::string& what) {
  cmd.add_option("-c,--config", choices.config_path, "Rig file (TOML); default: the embedded rig")
      ->check(CLI::ExistingFile);
  auto* sets = cmd.add_option("--sets", choices.sets,
                              "Number of double-frame sets (default: simulation.sets of a simulated rig, else until "
                              "Ctrl-C)");
  cmd.add_option("--duration", choices.duration_s, what + " for this many seconds")->excludes(sets);
  cmd.add_option("--pace", choices.pace,
                 "Simulated trigger: real-time (events at the rig's rate) | max (as fast as the recorder takes them)")
      ->capture_default_str();
  cmd.add_option("--on-camera-loss", choices.on_camera_loss,
                 "When a camera vanishes: stop (keep what was recorded) | continue (record its frames as missing)")
      ->capture_default_str();
  cmd.add_option("--status", choices.status, "Where the JSON status PUB socket binds; none: no socket")
      ->capture_default_str();
  cmd.add_option("--inject-fault", choices.faults,
                 "Testing: make a simulated camera fail, CAMERA:vanish-after=EVENTS (repeatable)");
}

config::RigConfig load_rig(const RigRunChoices& choices) {
  return choices.config_path.empty() ? config::default_rig_config() : config::load_rig_config(choices.config_path);
}

RigAcquisitionOptions rig_acquisition_options(const config::RigConfig& rig, const RigRunChoices& choices) {
  if (choices.sets && *choices.sets < 1)
    throw bad_input(fmt::format("--sets {} is invalid: must be >= 1", *choices.sets));
  const auto loss_policy = parse_camera_loss_policy(choices.on_camera_loss);
  if (!loss_policy)
    throw bad_input(fmt::format("--on-camera-loss {} is not supported: use stop or continue", choices.on_camera_loss));
  check_status_endpoint(choices.status);
  RigAcquisitionOptions options;
  options.sets = choices.sets;
  options.duration_s = choices.duration_s;
  if (!choices.sets && !choices.duration_s && rig.simulation && rig.simulation->sets > 0)
    options.sets = static_cast<std::uint64_t>(rig.simulation->sets);
  options.pacing = parse_pace(choices.pace);
  options.on_camera_loss = *loss_policy;
  for (const auto& fault : choices.faults) add_camera_fault(options.faults, fault);
  return options;
}

std::string run_length_text(const RigAcquisitionOptions& options) {
  if (options.sets) return fmt::format("{} sets", *options.sets);
  if (options.duration_s) return fmt::format("{:g} s", *options.duration_s);
  return "until Ctrl-C";
}

}  // namespace tomorig::rig
