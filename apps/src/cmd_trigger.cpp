// tomorig trigger plan [--config RIG] [--json]: the frame-straddling timing of a rig, checked
// against its light-source safety limits and its trigger device's capabilities.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/trigger/plan_diagram.h"
#include "tomorig/trigger/rig_trigger.h"

namespace tomorig::app {
namespace {

struct PlanOptions {
  std::string config_path;
  JsonOutput json;
};

double us(std::int64_t ns) { return static_cast<double>(ns) / 1000.0; }

nlohmann::json pulse_json(const trigger::Pulse& p) { return {{"rise_us", us(p.rise_ns)}, {"fall_us", us(p.fall_ns)}}; }

nlohmann::json plan_json(const std::string& rig_name, const trigger::TimingPlan& plan,
                         const trigger::DeviceCapabilities& device) {
  nlohmann::json channels = nlohmann::json::array();
  for (const auto& ch : plan.channels) {
    nlohmann::json pulses = nlohmann::json::array();
    for (const auto& p : ch.pulses) pulses.push_back(pulse_json(p));
    nlohmann::json c = {{"name", ch.spec.name},
                        {"role", config::to_string(ch.spec.role)},
                        {"delay_us", us(ch.spec.delay_ns)},
                        {"driven_by", trigger::device_drives(device, ch.spec) ? device.device : "pulse_generator"},
                        {"pulses", pulses}};
    if (!ch.spec.light_source.empty()) {
      c["light_source"] = ch.spec.light_source;
      c["makes"] = config::to_string(ch.spec.pulses);
    }
    if (ch.spec.wired()) c["gpio"] = {{"chip", ch.spec.chip}, {"line", ch.spec.line}};
    channels.push_back(c);
  }
  nlohmann::json sources = nlohmann::json::array();
  for (const auto& s : plan.light_sources) {
    const auto limits = trigger::resolve_limits(s);
    sources.push_back({{"name", s.name},
                       {"kind", config::to_string(s.kind)},
                       {"pulse_width_us", us(s.pulse_width_ns)},
                       {"limits",
                        {{"max_pulse_width_us", us(limits.max_pulse_width_ns)},
                         {"max_duty_cycle", limits.max_duty_cycle},
                         {"max_rate_hz", limits.max_rate_hz}}}});
  }
  return {{"rig", rig_name},
          {"feasible", true},
          {"rate_hz", plan.rate_hz},
          {"period_us", us(plan.period_ns)},
          {"dt_us", us(plan.dt_ns)},
          {"straddle_margin_us", us(plan.straddle_margin_ns)},
          {"camera",
           {{"exposure_a_us", us(plan.camera.exposure_a_ns)},
            {"interframe_us", us(plan.camera.interframe_ns)},
            {"exposure_b_us", us(plan.camera.exposure_b_ns)}}},
          {"frame_a", pulse_json(plan.frame_a)},
          {"frame_b", pulse_json(plan.frame_b)},
          {"light_pulse_1", pulse_json(plan.light_pulse_1)},
          {"light_pulse_2", pulse_json(plan.light_pulse_2)},
          {"device",
           {{"name", device.device},
            {"channels", device.max_channels},
            {"resolution_us", us(device.resolution_ns)},
            {"jitter_us", us(device.jitter_ns)},
            {"min_pulse_us", us(device.min_pulse_ns)}}},
          {"light_sources", sources},
          {"channels", channels}};
}

void print_plan(const PlanOptions& opt) {
  const config::RigConfig rig =
      opt.config_path.empty() ? config::default_rig_config() : config::load_rig_config(opt.config_path);
  const trigger::RigTrigger setup = trigger::rig_trigger(rig);
  // Throws bad_input (exit 2) naming what is infeasible, unsafe or beyond the device.
  const trigger::TimingPlan plan = trigger::plan_and_check(setup);
  const trigger::DeviceCapabilities device = setup.capabilities();
  if (opt.json.wanted()) {
    nlohmann::json j = json_summary("trigger plan");
    j.update(plan_json(rig.name, plan, device));
    emit_json(opt.json, j);
    if (opt.json.to_stdout()) return;
  }
  fmt::print("rig: {}\n{}", rig.name, trigger::timing_diagram(plan, device));
  fmt::print("feasible: within the light-source safety limits and the {} device's capabilities\n", device.device);
}

}  // namespace

void add_trigger_command(CLI::App& root) {
  CLI::App* trigger = root.add_subcommand("trigger", "Plan and check the trigger timing of a rig");
  trigger->require_subcommand(1);
  auto opt = std::make_shared<PlanOptions>();
  CLI::App* plan = trigger->add_subcommand(
      "plan",
      "Print the frame-straddling timing plan (one row per channel, edge times in us) and check it against the "
      "light-source safety limits and the trigger device; exit code 2 when infeasible");
  plan->add_option("--config", opt->config_path, "Rig configuration (TOML); default: the embedded simulated rig");
  add_json_flag(*plan, opt->json);
  plan->callback([opt] { print_plan(*opt); });
}

}  // namespace tomorig::app
