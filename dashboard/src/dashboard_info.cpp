#include "tomorig/dashboard/dashboard_info.h"

#include "tomorig/core/error.h"
#include "tomorig/pipeline/quicklook_settings.h"
#include "tomorig/trigger/plan_diagram.h"
#include "tomorig/trigger/rig_trigger.h"

namespace tomorig::dashboard {
namespace {

using nlohmann::json;

json target(const quicklook::Target& t) { return {{"low", t.low}, {"high", t.high}, {"amber", t.amber}}; }

json trigger_plan(const config::RigConfig& rig) {
  try {
    const trigger::RigTrigger setup = trigger::rig_trigger(rig);
    const trigger::TimingPlan plan = trigger::plan_and_check(setup);
    return {{"rate_hz", plan.rate_hz},
            {"dt_us", static_cast<double>(plan.dt_ns) / 1000.0},
            {"text", trigger::timing_diagram(plan, setup.capabilities())}};
  } catch (const Error& e) {
    return {{"error", e.what()}};  // shown on the page; the run itself refuses such a plan
  }
}

}  // namespace

json dashboard_info(const InfoSource& source) {
  const pipeline::QuickLookSettings settings = pipeline::quicklook_settings(source.rig);
  const quicklook::QuickLookTargets& t = settings.statistics.targets;
  return {{"mode", source.mode},
          {"source", source.source},
          {"rig", source.rig ? json(source.rig->name) : json(nullptr)},
          {"snapshots", source.snapshots},
          {"trigger_plan", source.rig ? trigger_plan(*source.rig) : json(nullptr)},
          {"targets",
           {{"ppp", target(t.ppp)},
            {"diameter_px", target(t.diameter_px)},
            {"source_density", target(t.source_density)},
            {"saturated_fraction", target(t.saturated_fraction)},
            {"energy_balance", target(t.energy_balance)},
            {"dt_displacement_px", target(settings.dt_check.displacement_px)},
            {"dt_valid_fraction", target(settings.dt_check.valid_fraction)},
            {"drift_warn_px", settings.drift.warn_px}}}};
}

}  // namespace tomorig::dashboard
