// 20 000 damaged wire messages into `tomorig record` (issue 14, item 7 and its acceptance): bit
// flips, truncations, random lengths and part-count changes of valid frame-set, session-start,
// set-truth and session-end messages, sent on a raw ZeroMQ PUSH socket between the genuine sets
// of one session. record must never stop, must account for every message (written sets +
// refused sets + rejected messages + session messages = messages sent), and the file must be
// valid afterwards and hold every genuine set, in order, with its pixels.
//
// Damage that turns a message into a well-formed start of another session or into the end of
// this one is not sent: record is meant to act on those (end the recording), so they are no
// test of robustness. Deterministic seed; TOMORIG_WIRE_FUZZ_MESSAGES overrides the count.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include <zmq.hpp>

#include "child_process.h"
#include "cli_runner.h"
#include "scripted_sender.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::testing {
namespace {

constexpr std::uint64_t kSession = 77;
// One message in this many is a genuine set of the session.
constexpr std::uint64_t kGenuineEvery = 8;

using Parts = std::vector<std::string>;

Parts bytes_of(std::vector<zmq::message_t>&& parts) {
  Parts out;
  for (auto& p : parts) out.emplace_back(static_cast<const char*>(p.data()), p.size());
  return out;
}
Parts bytes_of(zmq::message_t&& part) {
  std::vector<zmq::message_t> parts;
  parts.push_back(std::move(part));
  return bytes_of(std::move(parts));
}

std::vector<zmq::message_t> messages_of(const Parts& parts) {
  std::vector<zmq::message_t> out;
  for (const auto& p : parts) out.emplace_back(p.data(), p.size());
  return out;
}

// The valid messages damage starts from.
Parts valid_message(std::mt19937_64& rng, std::uint64_t genuine_sent) {
  switch (rng() % 4) {
    case 0: return bytes_of(stream::encode_session_start(small_start(kSession)));
    case 1: {
      stream::SetTruth truth{kSession, 100 + genuine_sent + rng() % 4, {}};
      truth.particles.particles_a = {{1.0, 2.0, 3.0}, {4.0, 5.0, 6.0}};
      truth.particles.particles_b = {{1.5, 2.5, 3.5}};
      return bytes_of(stream::encode_set_truth(truth));
    }
    case 2: return bytes_of(stream::encode_session_end({kSession, 3, stream::SessionOutcome::stopped, "Ctrl-C"}));
    default: return bytes_of(stream::encode_frame_set(small_set(genuine_sent + rng() % 4)));
  }
}

Parts damaged(Parts parts, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
  // Mostly the header (part 0): pixel parts are opaque to the decoder.
  std::string& part = parts[pick(4) != 0 || parts.size() == 1 ? 0 : 1 + pick(parts.size() - 1)];
  switch (pick(6)) {
    case 0:
    case 1:  // bit flips
      if (part.empty()) break;
      for (std::size_t k = 1 + pick(3); k > 0; --k) part[pick(part.size())] ^= static_cast<char>(1u << pick(8));
      break;
    case 2: part.resize(part.empty() ? 0 : pick(part.size())); break;  // truncation
    case 3: {  // random length, random bytes past the original ones
      const std::size_t old = part.size();
      part.resize(pick(2 * old + 16));
      for (std::size_t i = old; i < part.size(); ++i) part[i] = static_cast<char>(rng());
      break;
    }
    case 4:  // a part too many or too few
      if (pick(2) == 0 || parts.size() == 1) parts.emplace_back(pick(64), 'x');
      else parts.pop_back();
      break;
    default: {  // a random 16-bit field of the header overwritten (counts, lengths, versions)
      if (parts[0].size() < 2) break;
      const std::size_t at = pick(parts[0].size() - 1);
      parts[0][at] = static_cast<char>(rng());
      parts[0][at + 1] = static_cast<char>(pick(2) == 0 ? 0 : rng());
    }
  }
  return parts;
}

struct Expected {
  std::uint64_t rejected = 0;          // the decoder refuses them
  std::uint64_t frame_sets = 0;        // decoded sets: written or refused by the recorder
  std::uint64_t session_messages = 0;  // decoded start, truth and end messages
};

// What a damaged message is, decoded here; nullopt if record would rightly act on it (a new
// session's start, this session's end), so it is not sent.
std::optional<int> classify(const Parts& parts) {
  try {
    const stream::StreamMessage m = stream::decode_stream_message(messages_of(parts));
    if (const auto* start = std::get_if<stream::SessionStart>(&m); start && start->session_id != kSession)
      return std::nullopt;
    if (const auto* end = std::get_if<stream::SessionEnd>(&m); end && end->session_id == kSession)
      return std::nullopt;
    return std::holds_alternative<FrameSet>(m) ? 1 : 2;
  } catch (const Error&) {
    return 0;
  }
}

void send(zmq::socket_t& push, const Parts& parts) {
  for (std::size_t i = 0; i < parts.size(); ++i) {
    zmq::message_t m(parts[i].data(), parts[i].size());
    const auto sent = push.send(m, i + 1 < parts.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
    ASSERT_TRUE(sent.has_value()) << "record stopped taking messages";
  }
}

std::uint64_t number_before(const std::string& text, const std::string& what) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("(\\d+) " + what))) return ~std::uint64_t{0};
  return std::stoull(m[1]);
}

bool is_small_set(const FrameSet& set, std::uint64_t index) {
  if (set.trigger_index != 100 + index || set.cameras.size() != 2) return false;
  for (int c = 0; c < 2; ++c)
    for (const Frame* f : {&set.cameras[c].a, &set.cameras[c].b}) {
      if (f->image.empty()) return false;
      for (int y = 0; y < kSmallHeight; ++y)
        for (int x = 0; x < kSmallWidth; ++x)
          if (f->image.at<std::uint16_t>(x, y) != small_pixel(index, c, x, y)) return false;
    }
  return true;
}

TEST(RecordWireFuzz, DamagedMessagesAreCountedAndNeverStopTheRecording) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  const char* env = std::getenv("TOMORIG_WIRE_FUZZ_MESSAGES");
  const std::uint64_t total = env != nullptr ? std::strtoull(env, nullptr, 10) : 20000;
  TempDir dir;
  const auto out = dir / "fuzz.h5";
  zmq::context_t context;
  zmq::socket_t push(context, zmq::socket_type::push);
  push.set(zmq::sockopt::sndtimeo, 30000);  // record connects first, then keeps up
  push.set(zmq::sockopt::linger, 30000);
  push.bind("tcp://127.0.0.1:*");
  TomorigProcess record({"record", "--from", push.get(zmq::sockopt::last_endpoint), "-o", out.string(),
                         "--idle-timeout", "60"});

  std::mt19937_64 rng(14);
  Expected expected;
  std::uint64_t genuine = 0, sent = 0;
  send(push, bytes_of(stream::encode_session_start(small_start(kSession))));
  ++sent;
  ++expected.session_messages;
  while (sent < total) {
    if (sent % kGenuineEvery == 1) {
      send(push, bytes_of(stream::encode_frame_set(small_set(genuine++))));
      ++expected.frame_sets;
    } else {
      const Parts message = damaged(valid_message(rng, genuine), rng);
      const auto kind = classify(message);
      if (!kind) continue;
      send(push, message);
      ++(*kind == 0 ? expected.rejected : *kind == 1 ? expected.frame_sets : expected.session_messages);
    }
    if (::testing::Test::HasFatalFailure()) return;
    ++sent;
  }
  send(push, bytes_of(stream::encode_session_end({kSession, genuine, stream::SessionOutcome::completed, ""})));
  ++expected.session_messages;
  ASSERT_EQ(record.wait(), 0) << record.err();

  const std::string report = record.out();
  std::printf("sent %llu messages: %s", static_cast<unsigned long long>(sent + 1), report.c_str());  // for docs/reliability.md
  const std::uint64_t written = number_before(report, "sets \\(");
  const std::uint64_t refused = number_before(report, "refused sets");
  EXPECT_EQ(written + refused, expected.frame_sets) << report;
  EXPECT_EQ(number_before(report, "rejected messages"), expected.rejected) << report;
  EXPECT_EQ(number_before(report, "session messages"), expected.session_messages) << report;
  EXPECT_GT(expected.rejected, total / 4);  // the damage reached the decoder's checks
  EXPECT_GT(refused, 0u);                   // and the recorder's

  // Valid afterwards, and every genuine set is in it, in order (damaged sets that still
  // decode and match the session are written between them).
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  ASSERT_EQ(session.set_count(), written);
  std::uint64_t next = 0;
  for (std::uint64_t s = 0; s < session.set_count() && next < genuine; ++s)
    if (session.set_record(s).trigger_index == 100 + next && is_small_set(session.read_set(s), next)) ++next;
  EXPECT_EQ(next, genuine) << "genuine set " << next << " is not in the file in order";
}

}  // namespace
}  // namespace tomorig::testing
