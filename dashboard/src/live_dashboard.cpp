#include "tomorig/dashboard/live_dashboard.h"

#include <optional>

namespace tomorig::dashboard {

// Members are destroyed in reverse: the server stops serving the state before the feed stops
// filling it, and both before the state goes.
struct LiveDashboard::Parts {
  DashboardState state;
  std::optional<LiveFeed> feed;
  std::optional<DashboardServer> server;
};

LiveDashboard::LiveDashboard(InfoSource info, LiveFeedOptions feed, const DashboardServerOptions& server)
    : parts_(std::make_unique<Parts>()) {
  info.snapshots = !server.snapshot_folder.empty();
  parts_->state.set_info(dashboard_info(info));
  parts_->feed.emplace(parts_->state, std::move(feed));
  parts_->server.emplace(parts_->state, server);
}

LiveDashboard::~LiveDashboard() = default;

std::string LiveDashboard::url() const { return parts_->server->url(); }

const DashboardState& LiveDashboard::state() const { return parts_->state; }

void LiveDashboard::stop() { parts_->server->stop(); }

}  // namespace tomorig::dashboard
