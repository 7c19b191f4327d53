#pragma once
// A dashboard watching a live producer: the state, its feed from the quick-look and status
// streams, and the server, started in that order and stopped in reverse. `tomorig run`,
// `tomorig replay` and `tomorig preview --from` each serve one; it only subscribes, so it never
// holds the producer up.
#include <memory>
#include <string>

#include "tomorig/dashboard/dashboard_info.h"
#include "tomorig/dashboard/dashboard_server.h"
#include "tomorig/dashboard/dashboard_state.h"
#include "tomorig/dashboard/live_feed.h"

namespace tomorig::dashboard {

class LiveDashboard {
 public:
  // `info.snapshots` is taken from the server options. Throws what DashboardServer throws
  // (a taken or refused address) before anything is served.
  LiveDashboard(InfoSource info, LiveFeedOptions feed, const DashboardServerOptions& server);
  ~LiveDashboard();
  LiveDashboard(const LiveDashboard&) = delete;
  LiveDashboard& operator=(const LiveDashboard&) = delete;

  std::string url() const;
  const DashboardState& state() const;
  void stop();  // ends the server's event streams; idempotent

 private:
  struct Parts;
  std::unique_ptr<Parts> parts_;
};

}  // namespace tomorig::dashboard
