#pragma once
// The dashboard's HTTP server (cpp-httplib): the embedded page, its event stream (Server-Sent
// Events), the images as PNG, and the operator's safe actions (acknowledge an alarm, snapshot).
// Nothing here reaches the trigger, the cameras or the light sources: there is no endpoint for
// them. Endpoints and security: docs/dashboard.md.
#include <filesystem>
#include <memory>
#include <string>

#include "tomorig/dashboard/dashboard_state.h"

namespace tomorig::dashboard {

// Where the dashboard listens unless told otherwise (`--http` without a value).
inline constexpr const char* kDefaultHttpAddress = "127.0.0.1:8080";

struct HttpAddress {
  std::string host;  // "127.0.0.1", "localhost", "::1", "0.0.0.0", a card's address
  int port = 0;      // 0: any free port
};

// "HOST:PORT", "[V6]:PORT" or "PORT" (loopback). bad_input naming the text and the form.
HttpAddress parse_http_address(const std::string& text);
// 127.x.x.x, localhost, ::1.
bool is_loopback_host(const std::string& host);
// 32 hex digits from the system's random source.
std::string generate_token();

struct DashboardServerOptions {
  HttpAddress address{"127.0.0.1", 8080};
  // A non-loopback address is refused unless this is set, and then needs a token.
  bool allow_remote = false;
  // Required on every request when not empty: "Authorization: Bearer TOKEN" or "?token=TOKEN".
  std::string token;
  // Where POST /api/snapshot writes; empty: snapshots are refused (409).
  std::filesystem::path snapshot_folder;
  int threads = 24;      // connections served at once (each open page holds one for its events)
  int max_streams = 16;  // event streams at once; more are refused (503) so pages cannot starve requests
};

class DashboardServer {
 public:
  // Checks the address (bad_input: a remote host without allow_remote or without a token, a
  // bad port, an unusable snapshot folder), binds it (runtime_error naming the address when it
  // is taken), and serves `state` on a thread of its own until destroyed. `state` must outlive it.
  DashboardServer(DashboardState& state, DashboardServerOptions options);
  ~DashboardServer();  // stop()
  DashboardServer(const DashboardServer&) = delete;
  DashboardServer& operator=(const DashboardServer&) = delete;

  int port() const;  // the bound port (a requested 0 resolved)
  // http://HOST:PORT/ with ?token=... when there is one: what to open in a browser.
  std::string url() const;
  // Ends the event streams and the server; waits for its threads. Idempotent.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::dashboard
