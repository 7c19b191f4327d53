#include "tomorig/dashboard/dashboard_state.h"

#include <algorithm>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/pipeline/quicklook_view.h"
#include "tomorig/stream/status.h"

namespace tomorig::dashboard {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr int kQuickLookVersion = 1;
constexpr std::size_t kMaxAlarmKey = 200;
constexpr std::size_t kMaxAcknowledged = 1000;
constexpr std::string_view kPngSignature = "\x89PNG\r\n\x1a\n";

constexpr std::size_t index(Topic t) { return static_cast<std::size_t>(t); }

// The page draws figures, histograms and flags; the per-tile maps and the Δt windows are for
// scripts and would make every event several times larger.
void drop_bulk(json& j) {
  if (j.is_object()) {
    j.erase("map");
    j.erase("windows");
    for (auto& [key, value] : j.items()) drop_bulk(value);
  } else if (j.is_array()) {
    for (json& value : j) drop_bulk(value);
  }
}

}  // namespace

const char* topic_name(Topic topic) {
  switch (topic) {
    case Topic::info: return "info";
    case Topic::quicklook: return "quicklook";
    case Topic::preview: return "preview";
    case Topic::status: return "status";
    case Topic::alarms: return "alarms";
    case Topic::history: return "history";
    case Topic::count: break;
  }
  return "?";
}

struct DashboardState::Impl {
  mutable std::mutex mutex;
  mutable std::condition_variable changed;
  bool closed = false;
  std::array<std::uint64_t, index(Topic::count)> version{};
  std::array<std::string, index(Topic::count)> data;  // JSON text per topic
  std::map<std::string, std::string> images;          // name -> PNG bytes
  std::set<std::string> acknowledged;
  std::optional<stream::PreviewMessage> last_quicklook, last_preview;  // for snapshots
  std::uint64_t messages = 0;

  // Under the lock.
  void publish(Topic t, std::string text) {
    data[index(t)] = std::move(text);
    ++version[index(t)];
    changed.notify_all();
  }
  std::string alarms_text() const {
    return json{{"acknowledged", json(std::vector<std::string>(acknowledged.begin(), acknowledged.end()))}}.dump();
  }
};

DashboardState::DashboardState() : impl_(std::make_unique<Impl>()) {
  impl_->publish(Topic::alarms, impl_->alarms_text());
}
DashboardState::~DashboardState() = default;

void DashboardState::take_message(const stream::PreviewMessage& message) {
  json j = json::parse(message.json, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) throw bad_input("a preview message's JSON is not an object: not a tomorig quick-look message");
  const std::string type = j.value("type", std::string());
  if (type != "tomorig.quicklook" && type != "tomorig.preview")
    throw bad_input(fmt::format("a preview message of type '{}' is not a tomorig quick-look message", type));
  if (j.value("version", 0) != kQuickLookVersion)
    throw bad_input(fmt::format("the quick-look message is version {} but this dashboard reads version {}; run the "
                                "same tomorig release on both ends",
                                j.contains("version") ? j.at("version").dump() : "(none)", kQuickLookVersion));
  std::map<std::string, std::string> images;
  if (j.contains("images")) {
    if (!j.at("images").is_array()) throw bad_input("a quick-look message's 'images' is not an array");
    for (json& im : j.at("images")) {
      const std::string name = im.is_object() ? im.value("name", std::string()) : std::string();
      const std::size_t part = im.is_object() ? im.value("part", std::size_t{0}) : 0;
      if (name.empty() || part < 1 || part > message.images.size())
        throw bad_input(fmt::format("a quick-look message lists image {} for part {}, but it has {} image parts",
                                    im.dump(), part, message.images.size()));
      const std::string& png = message.images[part - 1];
      if (!png.starts_with(kPngSignature))
        throw bad_input(fmt::format("the quick-look message's image '{}' is not a PNG file", name));
      images[name] = png;
      im.erase("part");  // part numbers mean nothing to the page: it asks for images by name
    }
  }
  drop_bulk(j);
  const Topic topic = type == "tomorig.quicklook" ? Topic::quicklook : Topic::preview;
  std::string text = j.dump(-1, ' ', false, json::error_handler_t::replace);

  std::lock_guard lock(impl_->mutex);
  for (auto& [name, png] : images) impl_->images[name] = std::move(png);
  (topic == Topic::quicklook ? impl_->last_quicklook : impl_->last_preview) = message;
  ++impl_->messages;
  impl_->publish(topic, std::move(text));
}

void DashboardState::take_status(const std::string& text) {
  const stream::Status status = stream::parse_status(text);  // bad_input naming what is wrong
  std::string normalised = stream::to_json(status);
  std::lock_guard lock(impl_->mutex);
  impl_->publish(Topic::status, std::move(normalised));
}

void DashboardState::set_info(json info) {
  std::string text = info.dump(-1, ' ', false, json::error_handler_t::replace);
  std::lock_guard lock(impl_->mutex);
  impl_->publish(Topic::info, std::move(text));
}

void DashboardState::set_history(json history) {
  std::string text = history.dump(-1, ' ', false, json::error_handler_t::replace);
  std::lock_guard lock(impl_->mutex);
  impl_->publish(Topic::history, std::move(text));
}

void DashboardState::acknowledge(const std::string& key) {
  if (key.empty() || key.size() > kMaxAlarmKey)
    throw bad_input(fmt::format("an alarm key must have 1 to {} characters", kMaxAlarmKey));
  std::lock_guard lock(impl_->mutex);
  if (impl_->acknowledged.size() >= kMaxAcknowledged && !impl_->acknowledged.contains(key))
    throw bad_input(fmt::format("{} alarms are already acknowledged; restart the dashboard to clear them",
                                kMaxAcknowledged));
  if (impl_->acknowledged.insert(key).second) impl_->publish(Topic::alarms, impl_->alarms_text());
}

std::vector<std::string> DashboardState::acknowledged() const {
  std::lock_guard lock(impl_->mutex);
  return {impl_->acknowledged.begin(), impl_->acknowledged.end()};
}

std::optional<std::string> DashboardState::image(const std::string& name) const {
  std::lock_guard lock(impl_->mutex);
  const auto it = impl_->images.find(name);
  if (it == impl_->images.end()) return std::nullopt;
  return it->second;
}

json DashboardState::current() const {
  std::lock_guard lock(impl_->mutex);
  json out = json::object();
  for (std::size_t t = 0; t < index(Topic::count); ++t) {
    const std::string& text = impl_->data[t];
    out[topic_name(static_cast<Topic>(t))] = text.empty() ? json(nullptr) : json::parse(text);
  }
  return out;
}

std::vector<DashboardEvent> DashboardState::wait_events(EventCursor& cursor, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(impl_->mutex);
  const auto fresh = [&] {
    for (std::size_t t = 0; t < index(Topic::count); ++t)
      if (impl_->version[t] != cursor.seen[t]) return true;
    return false;
  };
  impl_->changed.wait_for(lock, timeout, [&] { return impl_->closed || fresh(); });
  std::vector<DashboardEvent> events;
  if (impl_->closed) return events;
  for (std::size_t t = 0; t < index(Topic::count); ++t) {
    if (impl_->version[t] == cursor.seen[t]) continue;
    cursor.seen[t] = impl_->version[t];
    events.push_back({topic_name(static_cast<Topic>(t)), impl_->data[t]});
  }
  return events;
}

void DashboardState::close() {
  std::lock_guard lock(impl_->mutex);
  impl_->closed = true;
  impl_->changed.notify_all();
}

bool DashboardState::closed() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->closed;
}

fs::path DashboardState::write_snapshot(const fs::path& folder) const {
  std::optional<stream::PreviewMessage> quicklook, preview;
  {
    std::lock_guard lock(impl_->mutex);
    quicklook = impl_->last_quicklook;
    preview = impl_->last_preview;
  }
  if (!quicklook) throw bad_input("no quick-look results have arrived yet: nothing to snapshot");
  const auto set = json::parse(quicklook->json).value("set", std::uint64_t{0});
  const fs::path file = folder / fmt::format("set_{:06}.png", set);
  if (fs::exists(file)) throw bad_input(fmt::format("{} exists already: a snapshot is never replaced", file.string()));
  // The `tomorig preview --png` picture: one view that writes every set it takes, given the
  // newest volume first and then the newest set. Existing snapshots of other sets are kept.
  pipeline::QuickLookView view({.png_folder = folder, .png_interval_s = 0, .overwrite = true});
  if (preview) view.take(*preview);
  view.take(*quicklook);
  if (view.snapshots().empty()) throw runtime_error(fmt::format("the snapshot of set {} was not written", set));
  return view.snapshots().back();
}

std::uint64_t DashboardState::messages() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->messages;
}

}  // namespace tomorig::dashboard
