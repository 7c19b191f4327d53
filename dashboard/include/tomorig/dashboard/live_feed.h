#pragma once
// Feeds a DashboardState from a running rig: subscribes to the quick-look stream that
// `tomorig run --preview` / `tomorig replay --preview` publish, and to the status stream of
// `tomorig run` / `tomorig acquire`, each on a thread of its own. The threads only receive and
// store (latest wins), so they keep up with the publishers and never make them drop a message
// for everybody (docs/wire-protocol.md, "Preview path").
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "tomorig/dashboard/dashboard_state.h"

namespace tomorig::dashboard {

struct LiveFeedOptions {
  std::string preview_endpoint;  // empty: no quick-look
  std::string status_endpoint;   // empty: no status
  // Told once per kind of problem (a malformed message, a failed socket), from a feed thread.
  std::function<void(const std::string&)> notice;
};

struct LiveFeedStats {
  std::uint64_t messages = 0;  // quick-look messages taken
  std::uint64_t statuses = 0;  // status messages taken
  std::uint64_t rejected = 0;  // messages that were not what they claimed
};

class LiveFeed {
 public:
  // Connects (never binds) and starts the threads. `state` must outlive the feed.
  LiveFeed(DashboardState& state, LiveFeedOptions options);
  ~LiveFeed();  // stops and joins the threads
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  LiveFeedStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::dashboard
