#include "tomorig/dashboard/dashboard_server.h"

#include <atomic>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <random>
#include <regex>
#include <thread>

#include <arpa/inet.h>
#include <sys/socket.h>
#include <fmt/format.h>
#include <httplib.h>

#include "tomorig/core/error.h"
#include "web_assets.h"

namespace tomorig::dashboard {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

// How long an event stream waits for news before it sends a comment line, which both keeps
// proxies from closing it and lets the server notice a browser that has gone.
constexpr auto kKeepAlive = 2000ms;
// How long stop() waits for the open event streams to send their end.
constexpr auto kStreamsEndTimeout = 2000ms;

const std::regex kGetPaths("/|/index\\.html|/dashboard\\.js|/dashboard\\.css|/events|/api/state|/api/history|/image/.+");
const std::regex kPostPaths("/api/ack|/api/snapshot");

void reply_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(-1, ' ', false, json::error_handler_t::replace), "application/json");
}

void reply_error(httplib::Response& res, int status, const std::string& message) {
  reply_json(res, status, json{{"error", message}});
}

// Same time whatever the guess, so a wrong token tells nothing about the right one.
bool same_token(const std::string& given, const std::string& expected) {
  if (given.size() != expected.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < given.size(); ++i)
    diff |= static_cast<unsigned char>(given[i] ^ expected[i]);
  return diff == 0;
}

// The host name a request was addressed to, without the port.
std::string host_of(const std::string& header) {
  if (header.starts_with('[')) return header.substr(1, header.find(']') - 1);
  return header.substr(0, header.rfind(':') == std::string::npos ? header.size() : header.rfind(':'));
}

}  // namespace

HttpAddress parse_http_address(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return bad_input(fmt::format("--http '{}' is invalid: {}; give HOST:PORT, e.g. {} (PORT 0: any free port)", text,
                                 why, kDefaultHttpAddress));
  };
  HttpAddress address{"127.0.0.1", 0};
  std::string port_text = text;
  if (text.starts_with('[')) {
    const auto close = text.find("]:");
    if (close == std::string::npos) throw bad("an IPv6 address needs the form [ADDRESS]:PORT");
    address.host = text.substr(1, close - 1);
    port_text = text.substr(close + 2);
  } else if (const auto colon = text.rfind(':'); colon != std::string::npos) {
    address.host = text.substr(0, colon);
    port_text = text.substr(colon + 1);
  }
  if (address.host.empty()) throw bad("the host is empty");
  if (port_text.empty() || port_text.size() > 5 || port_text.find_first_not_of("0123456789") != std::string::npos)
    throw bad("the port is not a number");
  address.port = std::stoi(port_text);
  if (address.port > 65535) throw bad("the port is above 65535");
  return address;
}

bool is_loopback_host(const std::string& host) {
  if (host == "localhost" || host == "::1") return true;
  in_addr v4{};
  return inet_pton(AF_INET, host.c_str(), &v4) == 1 && (ntohl(v4.s_addr) >> 24) == 127;
}

std::string generate_token() {
  std::random_device source;  // the kernel's random source on Linux
  std::string token;
  for (int i = 0; i < 4; ++i) token += fmt::format("{:08x}", source());
  return token;
}

struct DashboardServer::Impl {
  DashboardState& state;
  DashboardServerOptions options;
  httplib::Server server;
  std::thread thread;
  int port = 0;
  std::atomic<int> streams{0};
  std::mutex streams_mutex;                // with streams_ended: stop() waits for the open streams
  std::condition_variable streams_ended;
  std::atomic<bool> stopped{false};
  std::atomic<bool> listen_ended{false};

  Impl(DashboardState& s, DashboardServerOptions o) : state(s), options(std::move(o)) {}

  httplib::Server::HandlerResponse admit(const httplib::Request& req, httplib::Response& res) {
    if (!options.token.empty()) {
      std::string given = req.get_param_value("token");
      const std::string authorization = req.get_header_value("Authorization");
      if (authorization.starts_with("Bearer ")) given = authorization.substr(7);
      if (!same_token(given, options.token)) {
        reply_error(res, 401, "this dashboard needs its token: open the address it printed (with ?token=...)");
        return httplib::Server::HandlerResponse::Handled;
      }
    } else if (!is_loopback_host(host_of(req.get_header_value("Host")))) {
      // Bound to loopback without a token: a page of another site that renamed itself to
      // 127.0.0.1 (DNS rebinding) must not read the rig's figures.
      reply_error(res, 403, "this dashboard answers requests addressed to a loopback name only");
      return httplib::Server::HandlerResponse::Handled;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Content-Type-Options", "nosniff");
    // Everything the page uses comes from here: no CDN, no inline script.
    res.set_header("Content-Security-Policy", "default-src 'self'; img-src 'self' data: blob:; frame-ancestors 'none'");
    return httplib::Server::HandlerResponse::Unhandled;
  }

  void routes() {
    server.set_pre_routing_handler([this](const auto& req, auto& res) { return admit(req, res); });
    for (const WebAsset& asset : web_assets()) {
      const std::string path(asset.path);
      const auto serve = [asset](const httplib::Request&, httplib::Response& res) {
        res.set_content(std::string(asset.bytes), std::string(asset.content_type));
      };
      server.Get(path, serve);
      if (path == "/index.html") server.Get("/", serve);
    }
    server.Get("/api/state", [this](const auto&, auto& res) { reply_json(res, 200, state.current()); });
    server.Get("/api/history", [this](const auto&, auto& res) {
      const json history = state.current().at("history");
      if (history.is_null()) return reply_error(res, 404, "no session history: this dashboard shows a live run");
      reply_json(res, 200, history);
    });
    server.Get("/image/(.+)", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string name = req.matches[1];
      if (auto png = state.image(name)) return res.set_content(std::move(*png), "image/png");
      reply_error(res, 404, fmt::format("no image '{}' has arrived", name));
    });
    server.Get("/events", [this](const httplib::Request&, httplib::Response& res) { events(res); });
    server.Post("/api/ack", [this](const httplib::Request& req, httplib::Response& res) {
      const json body = json::parse(req.body, nullptr, /*allow_exceptions=*/false);
      if (!body.is_object() || !body.contains("key") || !body.at("key").is_string())
        return reply_error(res, 400, R"(the body must be a JSON object {"key": "ALARM KEY"})");
      try {
        state.acknowledge(body.at("key").get<std::string>());
      } catch (const Error& e) {
        return reply_error(res, 400, e.what());
      }
      reply_json(res, 200, json{{"acknowledged", state.acknowledged()}});
    });
    server.Post("/api/snapshot", [this](const httplib::Request&, httplib::Response& res) {
      if (options.snapshot_folder.empty())
        return reply_error(res, 409, "snapshots are off: start the dashboard with --snapshots FOLDER");
      try {
        reply_json(res, 200, json{{"file", state.write_snapshot(options.snapshot_folder).string()}});
      } catch (const Error& e) {
        reply_error(res, 409, e.what());
      }
    });
    // Only the methods above exist: another method on a known path is 405, anything else 404.
    const auto refuse = [](const httplib::Request& req, httplib::Response& res) {
      if (std::regex_match(req.path, kGetPaths)) {
        res.set_header("Allow", "GET");
        return reply_error(res, 405, fmt::format("{} {} is not allowed: the dashboard only reads here", req.method, req.path));
      }
      if (std::regex_match(req.path, kPostPaths)) {
        res.set_header("Allow", "POST");
        return reply_error(res, 405, fmt::format("{} {} is not allowed", req.method, req.path));
      }
      reply_error(res, 404, fmt::format("no {} here", req.path));
    };
    server.Post("(.*)", refuse);
    server.Put("(.*)", refuse);
    server.Delete("(.*)", refuse);
    server.Patch("(.*)", refuse);
    server.Options("(.*)", refuse);
    server.Get("(.*)", refuse);  // GET on a POST path, or an unknown path
  }

  // The page's event stream: every topic once at the start, then each change, newest value
  // only (a slow browser skips, it never queues), and a comment line when nothing changes.
  void events(httplib::Response& res) {
    if (++streams > options.max_streams) {
      stream_closed();
      return reply_error(res, 503, fmt::format("{} pages are watching already; close one", options.max_streams));
    }
    auto cursor = std::make_shared<EventCursor>();
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, cursor, first = true](std::size_t, httplib::DataSink& sink) mutable {
          std::string out;
          if (first) out = "retry: 1000\n\n";  // the browser reconnects after a second
          first = false;
          const std::vector<DashboardEvent> events = state.wait_events(*cursor, kKeepAlive);
          if (stopped || state.closed()) {
            // Tell the page the source has ended, so it stops reconnecting, and end the stream
            // cleanly (a last empty chunk) rather than cutting it.
            static constexpr std::string_view kEnd = "event: end\ndata: {}\n\n";
            sink.write(kEnd.data(), kEnd.size());
            sink.done();
            return true;
          }
          if (events.empty() && out.empty()) out = ": keep-alive\n\n";
          for (const DashboardEvent& e : events) out += fmt::format("event: {}\ndata: {}\n\n", e.name, e.data);
          return sink.write(out.data(), out.size());
        },
        [this](bool) { stream_closed(); });
  }

  void stream_closed() {
    {
      std::lock_guard lock(streams_mutex);
      --streams;
    }
    streams_ended.notify_all();
  }

  // Until every open event stream has ended, at most `timeout` (a page whose socket no longer
  // takes data is left to the server's write timeout).
  void wait_for_streams(std::chrono::milliseconds timeout) {
    std::unique_lock lock(streams_mutex);
    streams_ended.wait_for(lock, timeout, [this] { return streams.load() <= 0; });
  }
};

DashboardServer::DashboardServer(DashboardState& state, DashboardServerOptions options)
    : impl_(std::make_unique<Impl>(state, std::move(options))) {
  const DashboardServerOptions& o = impl_->options;
  const std::string shown = o.address.host.find(':') != std::string::npos
                                ? fmt::format("[{}]:{}", o.address.host, o.address.port)
                                : fmt::format("{}:{}", o.address.host, o.address.port);
  if (o.address.port < 0 || o.address.port > 65535)
    throw bad_input(fmt::format("dashboard port {} is invalid: give 1-65535, or 0 for any free port", o.address.port));
  if (!is_loopback_host(o.address.host)) {
    if (!o.allow_remote)
      throw bad_input(fmt::format("refusing to serve the dashboard on {}: it would accept connections from other "
                                  "hosts. Bind to loopback (e.g. --http 127.0.0.1:8080), or pass --http-allow-remote "
                                  "to expose it on purpose (with a token)",
                                  shown));
    if (o.token.empty())
      throw bad_input(fmt::format("refusing to serve the dashboard on {} without a token: a remote address needs one "
                                  "(--http-token, or let tomorig generate it)",
                                  shown));
  }
  if (o.threads < 2 || o.max_streams < 1 || o.max_streams >= o.threads)
    throw bad_input(fmt::format("dashboard threads {} / event streams {}: need 1 <= streams < threads", o.threads,
                                o.max_streams));
  if (!o.snapshot_folder.empty()) {
    std::error_code ec;
    fs::create_directories(o.snapshot_folder, ec);
    if (ec || !fs::is_directory(o.snapshot_folder))
      throw bad_input(fmt::format("cannot use '{}' for snapshots: {}; choose another --snapshots folder",
                                  o.snapshot_folder.string(), ec ? ec.message() : "it is not a folder"));
  }

  httplib::Server& server = impl_->server;
  const int threads = o.threads;
  server.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  // SO_REUSEADDR (a restart finds the port free at once) but not httplib's SO_REUSEPORT, with
  // which a second dashboard would share the port silently instead of being told it is taken.
  server.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  server.set_keep_alive_timeout(2);  // idle browser connections give their thread back soon
  server.set_read_timeout(5);
  server.set_write_timeout(5);       // a browser that stops reading loses its stream, not a thread
  impl_->routes();

  if (o.address.port == 0) {
    impl_->port = server.bind_to_any_port(o.address.host);
    if (impl_->port <= 0) throw runtime_error(fmt::format("cannot serve the dashboard on {}: binding failed", shown));
  } else {
    if (!server.bind_to_port(o.address.host, o.address.port))
      throw runtime_error(fmt::format("cannot serve the dashboard on {}: the address is in use or not this host's; "
                                      "choose another --http",
                                      shown));
    impl_->port = o.address.port;
  }
  impl_->thread = std::thread([this] {
    impl_->server.listen_after_bind();
    impl_->listen_ended = true;
  });
  // stop() only reaches a server that has entered its accept loop.
  while (!impl_->server.is_running() && !impl_->listen_ended) std::this_thread::yield();
  if (impl_->listen_ended) {
    impl_->thread.join();
    impl_->stopped = true;
    throw runtime_error(fmt::format("the dashboard on {} could not start listening", shown));
  }
}

DashboardServer::~DashboardServer() { stop(); }

int DashboardServer::port() const { return impl_->port; }

std::string DashboardServer::url() const {
  const std::string& host = impl_->options.address.host;
  const std::string shown = host == "0.0.0.0" ? "127.0.0.1" : host.find(':') != std::string::npos ? "[" + host + "]" : host;
  std::string url = fmt::format("http://{}:{}/", shown, impl_->port);
  if (!impl_->options.token.empty()) url += "?token=" + impl_->options.token;
  return url;
}

void DashboardServer::stop() {
  if (impl_->stopped.exchange(true)) return;
  impl_->state.close();  // event streams waiting for news return now
  // Every open page is told "event: end" before the server stops: once it has stopped, the
  // server no longer calls a stream's provider, so a stream caught between two calls (its last
  // event just written) would be cut without it, and the page would keep reconnecting.
  impl_->wait_for_streams(kStreamsEndTimeout);
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

}  // namespace tomorig::dashboard
