#include "tomorig/dashboard/live_feed.h"

#include <atomic>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <zmq.hpp>

#include "tomorig/core/error.h"
#include "tomorig/stream/preview.h"
#include "tomorig/stream/status.h"

namespace tomorig::dashboard {
namespace {
using namespace std::chrono_literals;
// How often a quiet subscriber looks whether the feed is ending.
constexpr auto kWakeUp = 200ms;
}  // namespace

struct LiveFeed::Impl {
  DashboardState& state;
  LiveFeedOptions options;
  zmq::context_t context{1};
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> messages{0}, statuses{0}, rejected{0};
  std::mutex told_mutex;
  std::set<std::string> told;
  std::thread preview_thread, status_thread;

  Impl(DashboardState& s, LiveFeedOptions o) : state(s), options(std::move(o)) {}

  void tell(const std::string& kind, const std::string& text) {
    if (!options.notice) return;
    std::lock_guard lock(told_mutex);
    if (told.insert(kind).second) options.notice(text);
  }

  template <typename Receive, typename Take>
  void pump(const std::string& what, const std::string& endpoint, Receive receive, Take take) {
    try {
      while (!stopping) {
        try {
          auto message = receive();
          if (message) take(*message);
        } catch (const Error& e) {
          ++rejected;
          tell(what + " message", fmt::format("dashboard: a {} message from {} was ignored: {}", what, endpoint, e.what()));
        }
      }
    } catch (const std::exception& e) {
      tell(what + " socket", fmt::format("dashboard: the {} stream from {} failed: {}", what, endpoint, e.what()));
    }
  }
};

LiveFeed::LiveFeed(DashboardState& state, LiveFeedOptions options)
    : impl_(std::make_unique<Impl>(state, std::move(options))) {
  Impl& d = *impl_;
  // Sockets are made here, so a malformed endpoint is the caller's error, not a thread's.
  std::shared_ptr<stream::PreviewSubscriber> preview;
  std::shared_ptr<stream::StatusSubscriber> status;
  if (!d.options.preview_endpoint.empty()) {
    stream::SocketOptions socket = stream::preview_socket_options(d.options.preview_endpoint);
    socket.endpoint.bind = false;
    socket.timeout = kWakeUp;
    preview = std::make_shared<stream::PreviewSubscriber>(d.context, socket);
  }
  if (!d.options.status_endpoint.empty()) {
    stream::SocketOptions socket = stream::status_socket_options(d.options.status_endpoint);
    socket.endpoint.bind = false;
    socket.timeout = kWakeUp;
    status = std::make_shared<stream::StatusSubscriber>(d.context, socket);
  }
  if (preview)
    d.preview_thread = std::thread([&d, preview] {
      d.pump("quick-look", d.options.preview_endpoint, [&] { return preview->receive_message(); },
             [&](const stream::PreviewMessage& m) {
               d.state.take_message(m);
               ++d.messages;
             });
    });
  if (status)
    d.status_thread = std::thread([&d, status] {
      d.pump("status", d.options.status_endpoint, [&] { return status->receive(); },
             [&](const stream::Status& s) {
               d.state.take_status(stream::to_json(s));
               ++d.statuses;
             });
    });
}

LiveFeed::~LiveFeed() {
  impl_->stopping = true;
  if (impl_->preview_thread.joinable()) impl_->preview_thread.join();
  if (impl_->status_thread.joinable()) impl_->status_thread.join();
}

LiveFeedStats LiveFeed::stats() const { return {impl_->messages, impl_->statuses, impl_->rejected}; }

}  // namespace tomorig::dashboard
