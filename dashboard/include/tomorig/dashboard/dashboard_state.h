#pragma once
// What the dashboard shows, shared between the threads that feed it (quick-look and status
// subscribers, a session's history) and the HTTP server's threads that serve it. Latest wins:
// each topic keeps its newest value and a version number; a page's event stream asks for the
// topics that changed since it last looked, so a slow browser skips updates instead of queueing
// them, and no browser can hold up a feeder.
#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/stream/preview.h"

namespace tomorig::dashboard {

// The event names of the page's stream (docs/dashboard.md, "Endpoints").
enum class Topic : std::size_t { info, quicklook, preview, status, alarms, history, count };
const char* topic_name(Topic topic);

struct DashboardEvent {
  std::string name;  // topic_name
  std::string data;  // one JSON object on one line
};

// Which version of each topic a reader has seen; 0: none yet.
struct EventCursor {
  std::array<std::uint64_t, static_cast<std::size_t>(Topic::count)> seen{};
};

class DashboardState {
 public:
  DashboardState();
  ~DashboardState();
  DashboardState(const DashboardState&) = delete;
  DashboardState& operator=(const DashboardState&) = delete;

  // A quick-look message (docs/wire-protocol.md, "Quick-look messages"): its JSON, without the
  // bulky per-tile maps and Δt windows, becomes the quicklook or preview topic, and its PNG parts
  // the images served by name. Throws bad_input for a message that is not a tomorig quick-look
  // message of version 1 or whose image list does not match its parts.
  void take_message(const stream::PreviewMessage& message);
  // A status message (docs/wire-protocol.md, "Status messages"); bad_input if it is not one.
  void take_status(const std::string& json);
  // What the page shows about where its data comes from: mode ("live" or "session"), source,
  // trigger plan, quick-look targets, whether snapshots can be taken.
  void set_info(nlohmann::json info);
  // A recorded session's quick-look history (pipeline::to_json(QuickLookHistory)).
  void set_history(nlohmann::json history);

  // Operator acknowledges the alarm with this key (e.g. "drift:cam1", "camera:cam2"): the page
  // keeps showing it, marked as seen. Changes nothing but this list. bad_input for an empty or
  // overlong key.
  void acknowledge(const std::string& key);
  std::vector<std::string> acknowledged() const;

  // The newest PNG of this name ("cam0/a", "cam0/histogram", "mip_z", ...), if any.
  std::optional<std::string> image(const std::string& name) const;
  // Everything current as one object {info, quicklook, preview, status, alarms, history}, null
  // for what has not arrived.
  nlohmann::json current() const;
  // The topics that changed since `cursor`, newest values, in Topic order; waits up to `timeout`
  // for one if none has. Returns at once, empty, after close().
  std::vector<DashboardEvent> wait_events(EventCursor& cursor, std::chrono::milliseconds timeout) const;
  // Wakes every waiter for good (the server is stopping).
  void close();
  bool closed() const;

  // Writes the newest set's picture (thumbnails, histograms and numbers; the newest preview
  // volume's projections and profile) as <folder>/set_NNNNNN.png, the `tomorig preview --png`
  // snapshot. Returns the file. bad_input when nothing has arrived yet, or when that file exists
  // (a snapshot is never replaced).
  std::filesystem::path write_snapshot(const std::filesystem::path& folder) const;

  std::uint64_t messages() const;  // quick-look messages taken

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::dashboard
