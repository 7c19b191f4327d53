#pragma once
// The dashboard options `tomorig run` and `tomorig preview` share: --http [ADDR],
// --http-allow-remote, --http-token, --snapshots (docs/dashboard.md).
#include <string>
#include <vector>

#include "tomorig/config/rig_config.h"
#include "tomorig/dashboard/dashboard_server.h"

namespace CLI {
class App;
}

namespace tomorig::app {

struct HttpChoices {
  std::vector<std::string> http;  // --http [ADDR]: given with or without a value
  bool allow_remote = false;
  std::string token;
  std::string snapshots;
  bool given(const CLI::App& cmd) const;
};

void add_http_options(CLI::App& cmd, HttpChoices& choices);

// The server's options: the options first, then the rig file's [dashboard] (may be null) for
// the address when --http has no value and for allow_remote. A remote address allowed without
// --http-token gets a generated token (the URL the command prints carries it).
dashboard::DashboardServerOptions http_server_options(const HttpChoices& choices,
                                                      const config::DashboardConfig* rig = nullptr);

}  // namespace tomorig::app
