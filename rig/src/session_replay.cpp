#include "tomorig/rig/session_replay.h"

#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/core/error.h"
#include "tomorig/rig/send_with_retry.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/session_messages.h"

#include "rate_status_line.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::duration_cast;

double seconds_since(Clock::time_point t) { return duration<double>(Clock::now() - t).count(); }

// "replay: 12 sets sent  9.9 sets/s  41.9 MB/s  0 blocked sends": redrawn on a terminal, a
// plain line every few seconds into a log.
class ReplayStatus {
 public:
  explicit ReplayStatus(bool enabled) : line_(enabled) {}

  void update(const stream::SenderStats& s, std::uint64_t blocked_sets, bool final = false) {
    line_.update(s.sets_sent, s.bytes_sent, final, [&](const RateStatusLine::Rates& rates) {
      return fmt::format("replay: {} sets sent  {:.1f} sets/s  {:.1f} MB/s  {} blocked sends", s.sets_sent,
                         rates.sets_per_second, rates.mb_per_second, blocked_sets);
    });
  }
  void break_line() { line_.break_line(); }

 private:
  RateStatusLine line_;
};

// Waits until `due`; true if a stop was asked for meanwhile.
bool wait_until(Clock::time_point due, const StopSignalGuard* stop) {
  if (stop) return stop->wait_for(due - Clock::now());
  std::this_thread::sleep_until(due);
  return false;
}

}  // namespace

void SessionReplayOptions::validate() const {
  if (!(timeout_s > 0.0) || !(wait_s > 0.0))
    throw bad_input(fmt::format("--timeout {:g} / --wait {:g} are invalid: both must be > 0 seconds", timeout_s, wait_s));
}

std::string SessionReplayReport::brief() const {
  return fmt::format("replayed {} sets ({:.1f} MB) from {} on {}{}", sets_sent, static_cast<double>(bytes_sent) / 1e6,
                     session, endpoint, stopped ? fmt::format(", stopped by {}", stopped_by) : std::string());
}

struct SessionReplay::Impl {
  SessionReplayOptions options;
  ReplayRate rate;
  storage::SessionReader session;
  SetRange range;
  ReplaySchedule schedule;

  explicit Impl(SessionReplayOptions o)
      : options((o.validate(), std::move(o))), rate(parse_replay_rate(options.rate)), session(options.session) {
    if (session.set_count() == 0)
      throw bad_input(fmt::format("session '{}' holds no sets: nothing to replay", options.session.string()));
    range = options.sets.empty() ? SetRange{0, session.set_count()} : parse_set_range(options.sets, session.set_count());
    std::vector<std::int64_t> trigger_ns;
    for (std::uint64_t i = range.first; i < range.last; ++i)
      trigger_ns.push_back(session.set_record(i).trigger_timestamp_ns);
    schedule = make_replay_schedule(rate, trigger_ns);
  }

  SessionReplayReport run(const SessionReplayHooks& hooks);
};

SessionReplay::SessionReplay(SessionReplayOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
SessionReplay::~SessionReplay() = default;

const storage::SessionReader& SessionReplay::session() const { return impl_->session; }
SetRange SessionReplay::range() const { return impl_->range; }
SessionReplayReport SessionReplay::run(const SessionReplayHooks& hooks) { return impl_->run(hooks); }

SessionReplayReport SessionReplay::Impl::run(const SessionReplayHooks& hooks) {
  const StopSignalGuard* stop = hooks.stop;
  const auto stop_requested = [stop] { return stop && stop->stop_requested(); };
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {options.to, !options.connect, options.allow_remote};
  socket.endpoint.token = options.token;
  socket.timeout = duration_cast<std::chrono::milliseconds>(duration<double>(options.timeout_s));
  auto sender = std::make_unique<stream::FrameSender>(context, socket);
  if (hooks.sending) hooks.sending(sender->endpoint());

  stream::SessionStart start;
  start.session_id = stream::new_session_id();
  start.info = session.info();
  if (session.has_truth()) start.truth = session.truth();

  ReplayStatus status(options.status_line);
  SessionReplayReport report;
  report.session = options.session.string();
  report.range = range;
  // The first message waits (up to --wait) for a receiver.
  report.announced = send_with_retry(*sender, start, options.wait_s, stop) == SendOutcome::sent;
  bool stopped = !report.announced;
  auto pass_start = Clock::now();
  do {
    for (std::uint64_t i = range.first; i < range.last && !stopped; ++i) {
      if (wait_until(pass_start + schedule.due[i - range.first], stop)) {
        stopped = true;
        break;
      }
      FrameSet set = session.read_set(i);
      set.set_index = i;
      const std::uint64_t blocked_before = sender->stats().blocked_sends;
      if (session.has_truth_set(i))
        send_with_retry(*sender, stream::SetTruth{start.session_id, set.trigger_index, session.truth_set(i)},
                        options.timeout_s, nullptr);
      stopped = send_with_retry(*sender, set, options.timeout_s, stop) == SendOutcome::stopped;
      if (sender->stats().blocked_sends != blocked_before) ++report.blocked_sets;
      if (hooks.sent && !stopped) hooks.sent(set);
      status.update(sender->stats(), report.blocked_sets);
    }
    pass_start = rate.mode == ReplayRate::Mode::max ? Clock::now() : pass_start + schedule.pass_length;
  } while (options.loop && !stopped && !stop_requested());
  report.stopped = stopped || stop_requested();
  report.stopped_by = report.stopped && stop ? stop->signal_name() : "";
  if (report.announced) {
    // The end of the session: the recorder closes its file once it has the sets sent before.
    stream::SessionEnd end;
    end.session_id = start.session_id;
    end.sets_sent = sender->stats().sets_sent;
    if (report.stopped) {
      end.outcome = stream::SessionOutcome::stopped;
      end.reason = fmt::format("replay stopped by {}", report.stopped_by);
    }
    try {
      send_with_retry(*sender, end, options.timeout_s, nullptr);
    } catch (const Error& e) {
      if (!report.stopped) throw;
      // Stopped by the operator, typically after the recorder: nobody is left to tell.
      status.break_line();
      if (hooks.notice) hooks.notice(e.what());
    }
  }

  // Hand every queued set to the transport: closing the context waits (up to the linger, one
  // --timeout) until ZeroMQ has written all queued messages to the receiver. Waiting the whole
  // linger means it gave up with sets still queued.
  const stream::SenderStats sent = sender->stats();
  report.endpoint = sender->endpoint();
  report.sets_sent = sent.sets_sent;
  report.bytes_sent = sent.bytes_sent;
  sender.reset();
  const auto closing = Clock::now();
  context.close();
  if (seconds_since(closing) + 0.05 >= options.timeout_s)
    report.failure = fmt::format("the receiver on {} stopped taking sets: sets still queued after {:g} s were lost ({} "
                                 "sets were handed to the transport)",
                                 report.endpoint, options.timeout_s, sent.sets_sent);
  status.update(sent, report.blocked_sets, /*final=*/true);
  return report;
}

}  // namespace tomorig::rig
