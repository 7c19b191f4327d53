#include "http_options.h"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::app {

bool HttpChoices::given(const CLI::App& cmd) const { return cmd.count("--http") > 0; }

void add_http_options(CLI::App& cmd, HttpChoices& c) {
  cmd.add_option("--http", c.http,
                 fmt::format("Serve the operator's dashboard in a browser at HOST:PORT (port 0: any free port); "
                             "without a value {}",
                             dashboard::kDefaultHttpAddress))
      ->expected(0, 1);
  cmd.add_flag("--http-allow-remote", c.allow_remote,
               "Allow the dashboard on a non-loopback address (then a token is required on every request); the rig "
               "file's [dashboard] allow_remote does the same");
  cmd.add_option("--http-token", c.token,
                 "Token the dashboard requires on every request (default: none on loopback, generated for a remote "
                 "address)");
  cmd.add_option("--snapshots", c.snapshots, "Folder where the dashboard's Snapshot button writes PNG files");
}

dashboard::DashboardServerOptions http_server_options(const HttpChoices& c, const config::DashboardConfig* rig) {
  dashboard::DashboardServerOptions o;
  // `--http` without a value reaches here as one empty value (CLI11).
  if (!c.http.empty() && !c.http.front().empty()) {
    o.address = dashboard::parse_http_address(c.http.front());
  } else if (rig && !rig->http.empty()) {
    try {
      o.address = dashboard::parse_http_address(rig->http);
    } catch (const Error& e) {
      throw bad_input(fmt::format("the rig file's [dashboard] http: {}", e.what()));
    }
  } else {
    o.address = dashboard::parse_http_address(dashboard::kDefaultHttpAddress);
  }
  o.allow_remote = c.allow_remote || (rig && rig->allow_remote);
  o.token = c.token;
  if (!o.token.empty() && (o.token.size() < 16 || o.token.find_first_of(" \t\r\n&?#%") != std::string::npos))
    throw bad_input("--http-token must have at least 16 characters and no spaces or &?#%");
  if (o.token.empty() && o.allow_remote && !dashboard::is_loopback_host(o.address.host))
    o.token = dashboard::generate_token();
  o.snapshot_folder = c.snapshots;
  return o;
}

}  // namespace tomorig::app
