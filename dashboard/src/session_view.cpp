#include "tomorig/dashboard/session_view.h"

#include <optional>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/dashboard/dashboard_info.h"
#include "tomorig/pipeline/quicklook_history.h"

namespace tomorig::dashboard {

std::optional<config::RigConfig> session_rig(const storage::SessionReader& session) {
  try {
    if (!session.info().rig_config_toml.empty())
      return config::parse_rig_config(session.info().rig_config_toml, session.path().string());
  } catch (const Error&) {
  }
  return std::nullopt;
}

void show_session(DashboardState& state, const storage::SessionReader& session) {
  const pipeline::QuickLookHistory history = pipeline::quicklook_history(session);
  if (history.sets == 0)
    throw bad_input(fmt::format("{} holds no quick-look history: record with 'tomorig run --preview' (or --stage "
                                "quicklook) to keep one",
                                session.path().string()));
  const std::optional<config::RigConfig> rig = session_rig(session);
  nlohmann::json info = dashboard_info({.mode = "session", .source = session.path().string(), .rig = rig ? &*rig : nullptr});
  info["sets_recorded"] = session.set_count();
  info["created_utc"] = session.info().created_utc;
  state.set_info(std::move(info));
  state.set_history(pipeline::to_json(history));
}

}  // namespace tomorig::dashboard
