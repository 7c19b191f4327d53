#include "decode.h"

namespace tomorig::config::detail {

void decode_dashboard(TableReader& root, DashboardConfig& dashboard) {
  auto r = root.table("dashboard");
  if (!r) return;
  // The address itself is checked where it is used (dashboard::parse_http_address), which
  // names this key.
  r->read("http", dashboard.http, Need::optional, not_empty());
  r->read("allow_remote", dashboard.allow_remote);
  r->report_unknown_keys();
}

}  // namespace tomorig::config::detail
