// Session start, set truth and session end on the wire: exact round trips, the documented byte
// layout, a reasoned refusal of damaged messages (every truncation, randomised damage), and the
// messages travelling in order with frame sets through the lossless sockets.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <limits>
#include <random>

#include <zmq.hpp>

#include "stream_test_support.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream {
namespace {
using namespace std::chrono_literals;
using testing::expect_error;
using testing::expect_same_set;
using testing::pattern_set;

storage::SessionTruth sample_truth() {
  storage::SessionTruth t;
  t.case_name = "tpiv-thesis";
  t.flow_name = "taylor-green";
  t.flow_parameters = R"({"A_voxel":5,"p_voxel":256})";
  t.seed = 0x1234567890abcdefull;
  t.ppp = 0.05;
  for (int c = 0; c < 2; ++c) {
    storage::TruthCamera cam;
    cam.id = "cam" + std::to_string(c);
    for (int i = 0; i < 9; ++i) {
      cam.K[i] = 1000.5 * (i + 1) + c;
      cam.R[i] = (i % 4 == 0 ? 1.0 : 0.0) - 1e-3 * c;
    }
    cam.t = {1.5 * c, -2.25, 400.125};
    cam.width = 640;
    cam.height = 480 + c;
    t.cameras.push_back(cam);
  }
  return t;
}

SessionStart sample_start(bool with_truth) {
  SessionStart s;
  s.session_id = 0xfeedfacecafebeefull;
  s.info.rig_config_toml = "name = \"test rig\"\n[trigger]\nrate_hz = 10.0\n# ünïcode\n";
  s.info.software_version = "0.9.1-test";
  s.info.created_utc = "2026-11-23T12:27:00Z";
  s.info.cameras = {{"cam0", 640, 480, PixelFormat::Mono16, 6.5},
                    {"cam1", 640, 481, PixelFormat::Mono12, 3.45},
                    {"GVA-serial-7", 0, 0, PixelFormat::Mono8, 0.0}};  // size unknown until the first set
  if (with_truth) s.truth = sample_truth();
  return s;
}

SetTruth sample_set_truth() {
  SetTruth t;
  t.session_id = 0xfeedfacecafebeefull;
  t.trigger_index = 77;
  t.particles.particles_a = {{1.0, 2.0, 3.0}, {-4.5, 0.25, 1e-9}};
  t.particles.particles_b = {{1.5, 2.5, 3.5}};
  return t;
}

SessionEnd sample_end() {
  SessionEnd e;
  e.session_id = 0xfeedfacecafebeefull;
  e.sets_sent = 200;
  e.outcome = SessionOutcome::failed;
  e.reason = "camera cam2 vanished at trigger 51";
  return e;
}

std::vector<std::byte> bytes_of(const zmq::message_t& m) {
  const auto* p = static_cast<const std::byte*>(m.data());
  return {p, p + m.size()};
}

std::vector<zmq::message_t> one_part(const std::vector<std::byte>& bytes) {
  std::vector<zmq::message_t> parts;
  parts.emplace_back(bytes.data(), bytes.size());
  return parts;
}

StreamMessage decode_bytes(const std::vector<std::byte>& bytes) { return decode_stream_message(one_part(bytes)); }

std::uint64_t get_le(const std::vector<std::byte>& b, std::size_t at, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(b.at(at + i)) << (8 * i);
  return v;
}
void put_le(std::vector<std::byte>& b, std::size_t at, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b.at(at + i) = std::byte((v >> (8 * i)) & 0xff);
}

void expect_same_cameras(const std::vector<storage::SessionCamera>& got,
                         const std::vector<storage::SessionCamera>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i].id, want[i].id);
    EXPECT_EQ(got[i].width, want[i].width);
    EXPECT_EQ(got[i].height, want[i].height);
    EXPECT_EQ(got[i].pixel_format, want[i].pixel_format);
    EXPECT_EQ(got[i].pixel_pitch_um, want[i].pixel_pitch_um);  // exact: binary64 on the wire
  }
}

void expect_same_truth(const storage::SessionTruth& got, const storage::SessionTruth& want) {
  EXPECT_EQ(got.case_name, want.case_name);
  EXPECT_EQ(got.flow_name, want.flow_name);
  EXPECT_EQ(got.flow_parameters, want.flow_parameters);
  EXPECT_EQ(got.seed, want.seed);
  EXPECT_EQ(got.ppp, want.ppp);
  ASSERT_EQ(got.cameras.size(), want.cameras.size());
  for (std::size_t i = 0; i < want.cameras.size(); ++i) {
    EXPECT_EQ(got.cameras[i].id, want.cameras[i].id);
    EXPECT_EQ(got.cameras[i].model, want.cameras[i].model);
    EXPECT_EQ(got.cameras[i].K, want.cameras[i].K);
    EXPECT_EQ(got.cameras[i].R, want.cameras[i].R);
    EXPECT_EQ(got.cameras[i].t.x, want.cameras[i].t.x);
    EXPECT_EQ(got.cameras[i].t.y, want.cameras[i].t.y);
    EXPECT_EQ(got.cameras[i].t.z, want.cameras[i].t.z);
    EXPECT_EQ(got.cameras[i].width, want.cameras[i].width);
    EXPECT_EQ(got.cameras[i].height, want.cameras[i].height);
  }
}

void expect_same_particles(const std::vector<Vec3d>& got, const std::vector<Vec3d>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i].x, want[i].x);
    EXPECT_EQ(got[i].y, want[i].y);
    EXPECT_EQ(got[i].z, want[i].z);
  }
}

TEST(SessionMessages, StartRoundTripIsExact) {
  for (const bool with_truth : {false, true}) {
    const SessionStart want = sample_start(with_truth);
    const StreamMessage got = decode_stream_message(one_part(bytes_of(encode_session_start(want))));
    ASSERT_TRUE(std::holds_alternative<SessionStart>(got));
    const auto& start = std::get<SessionStart>(got);
    EXPECT_EQ(start.session_id, want.session_id);
    EXPECT_EQ(start.info.rig_config_toml, want.info.rig_config_toml);
    EXPECT_EQ(start.info.software_version, want.info.software_version);
    EXPECT_EQ(start.info.created_utc, want.info.created_utc);
    expect_same_cameras(start.info.cameras, want.info.cameras);
    ASSERT_EQ(start.truth.has_value(), with_truth);
    if (with_truth) expect_same_truth(*start.truth, *want.truth);
  }
}

TEST(SessionMessages, TruthAndEndRoundTripsAreExact) {
  const SetTruth truth = sample_set_truth();
  const StreamMessage a = decode_stream_message(one_part(bytes_of(encode_set_truth(truth))));
  ASSERT_TRUE(std::holds_alternative<SetTruth>(a));
  EXPECT_EQ(std::get<SetTruth>(a).session_id, truth.session_id);
  EXPECT_EQ(std::get<SetTruth>(a).trigger_index, 77u);
  expect_same_particles(std::get<SetTruth>(a).particles.particles_a, truth.particles.particles_a);
  expect_same_particles(std::get<SetTruth>(a).particles.particles_b, truth.particles.particles_b);

  for (const auto outcome : {SessionOutcome::completed, SessionOutcome::stopped, SessionOutcome::failed}) {
    SessionEnd end = sample_end();
    end.outcome = outcome;
    const StreamMessage b = decode_stream_message(one_part(bytes_of(encode_session_end(end))));
    ASSERT_TRUE(std::holds_alternative<SessionEnd>(b));
    EXPECT_EQ(std::get<SessionEnd>(b).session_id, end.session_id);
    EXPECT_EQ(std::get<SessionEnd>(b).sets_sent, 200u);
    EXPECT_EQ(std::get<SessionEnd>(b).outcome, outcome);
    EXPECT_EQ(std::get<SessionEnd>(b).reason, end.reason);
  }
}

TEST(SessionMessages, FrameSetsStillDecodeThroughTheGeneralDecoder) {
  const FrameSet set = pattern_set(4, 2, 16, 8, SampleType::u16);
  const StreamMessage m = decode_stream_message(encode_frame_set(set));
  ASSERT_TRUE(std::holds_alternative<FrameSet>(m));
  expect_same_set(std::get<FrameSet>(m), set);
  // ... and decode_frame_set names a session message it is handed instead of a set.
  expect_error([] { decode_frame_set(one_part(bytes_of(encode_session_end(sample_end())))); }, ErrorKind::bad_input,
               {"message type 4", "session end", "not a frame set"});
}

// Offsets as docs/wire-protocol.md lists them.
TEST(SessionMessages, LayoutMatchesTheDocument) {
  SessionStart start = sample_start(false);
  start.info.cameras.resize(1);
  start.info.rig_config_toml = "ab";
  start.info.software_version = "v";
  start.info.created_utc = "";
  const auto s = bytes_of(encode_session_start(start));
  EXPECT_EQ(std::memcmp(s.data(), "TMRG", 4), 0);
  EXPECT_EQ(get_le(s, 4, 2), 1u);                           // protocol version
  EXPECT_EQ(get_le(s, 6, 2), 2u);                           // session start
  EXPECT_EQ(get_le(s, 8, 2), kSessionFormatVersion);        // session format version
  EXPECT_EQ(get_le(s, 10, 2), 0u);                          // flags: no truth
  EXPECT_EQ(get_le(s, 12, 2), 1u);                          // cameras
  EXPECT_EQ(get_le(s, 14, 2), 0u);                          // reserved
  EXPECT_EQ(get_le(s, 16, 8), 0xfeedfacecafebeefull);       // session id
  EXPECT_EQ(get_le(s, 24, 4), 2u);                          // rig config: 2 bytes
  EXPECT_EQ(static_cast<char>(s[28]), 'a');
  EXPECT_EQ(get_le(s, 30, 4), 1u);                          // software version
  EXPECT_EQ(get_le(s, 35, 4), 0u);                          // created_utc (empty)
  EXPECT_EQ(get_le(s, 39, 2), 4u);                          // camera id length
  EXPECT_EQ(std::memcmp(s.data() + 41, "cam0", 4), 0);
  EXPECT_EQ(get_le(s, 45, 4), 640u);                        // width
  EXPECT_EQ(get_le(s, 49, 4), 480u);                        // height
  EXPECT_EQ(get_le(s, 53, 1), 3u);                          // Mono16
  EXPECT_EQ(get_le(s, 54, 3), 0u);                          // reserved
  double pitch = 0;
  const std::uint64_t pitch_bits = get_le(s, 57, 8);
  std::memcpy(&pitch, &pitch_bits, 8);
  EXPECT_EQ(pitch, 6.5);
  EXPECT_EQ(s.size(), 65u);

  const auto t = bytes_of(encode_set_truth(sample_set_truth()));
  EXPECT_EQ(get_le(t, 6, 2), 3u);
  EXPECT_EQ(get_le(t, 16, 8), 0xfeedfacecafebeefull);
  EXPECT_EQ(get_le(t, 24, 8), 77u);  // trigger index
  EXPECT_EQ(get_le(t, 32, 4), 2u);   // particles A
  EXPECT_EQ(get_le(t, 36, 4), 1u);   // particles B
  EXPECT_EQ(t.size(), 40u + 3 * 24);
  double x = 0;
  const std::uint64_t x_bits = get_le(t, 40 + 24, 8);  // second particle of A
  std::memcpy(&x, &x_bits, 8);
  EXPECT_EQ(x, -4.5);

  const auto e = bytes_of(encode_session_end(sample_end()));
  EXPECT_EQ(get_le(e, 6, 2), 4u);
  EXPECT_EQ(get_le(e, 10, 1), 2u);   // failed
  EXPECT_EQ(get_le(e, 24, 8), 200u); // sets sent
  EXPECT_EQ(get_le(e, 32, 4), sample_end().reason.size());
  EXPECT_EQ(e.size(), 36 + sample_end().reason.size());
}

// Every proper prefix of every kind of session message is refused with a reason: the decoder
// never reads past the end and never accepts half a message.
TEST(SessionMessages, EveryTruncationIsRejectedWithAReason) {
  const std::vector<std::vector<std::byte>> messages = {bytes_of(encode_session_start(sample_start(true))),
                                                        bytes_of(encode_set_truth(sample_set_truth())),
                                                        bytes_of(encode_session_end(sample_end()))};
  for (const auto& full : messages) {
    for (std::size_t n = 0; n < full.size(); ++n) {
      const std::vector<std::byte> cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
      try {
        decode_bytes(cut);
        ADD_FAILURE() << "a " << n << "-byte prefix of a " << full.size() << "-byte message was accepted";
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::bad_input);
        const std::string what = e.what();
        EXPECT_TRUE(what.find("truncated") != std::string::npos || what.find("carries") != std::string::npos)
            << "prefix " << n << ": " << what;
      }
    }
  }
}

class BadSessionMessage : public ::testing::Test {
 protected:
  static void expect_rejected(const std::vector<std::byte>& bytes, const std::vector<std::string>& words) {
    expect_error([&] { decode_bytes(bytes); }, ErrorKind::bad_input, words);
  }
  std::vector<std::byte> start_ = bytes_of(encode_session_start(sample_start(true)));
  std::vector<std::byte> truth_ = bytes_of(encode_set_truth(sample_set_truth()));
  std::vector<std::byte> end_ = bytes_of(encode_session_end(sample_end()));
};

TEST_F(BadSessionMessage, OtherSessionFormatVersionNamesBothVersions) {
  for (auto* m : {&start_, &truth_, &end_}) {
    put_le(*m, 8, 7, 2);
    expect_rejected(*m, {"session format version 7", "version " + std::to_string(kSessionFormatVersion)});
  }
}

TEST_F(BadSessionMessage, UnknownTypeAndFlagsAndOutcome) {
  put_le(start_, 6, 9, 2);
  expect_rejected(start_, {"message type 9", "unknown"});
  start_ = bytes_of(encode_session_start(sample_start(true)));
  put_le(start_, 10, 0x0003, 2);
  expect_rejected(start_, {"session-start", "flag bits 0x0002"});
  put_le(end_, 10, 3, 1);
  expect_rejected(end_, {"session-end", "outcome code 3"});
}

TEST_F(BadSessionMessage, TrailingBytesAndLyingCounts) {
  start_.push_back(std::byte{0});
  expect_rejected(start_, {"1 bytes follow the last field"});
  end_.push_back(std::byte{0});
  expect_rejected(end_, {"session-end", "follow the last field"});
  put_le(truth_, 32, 0xffffffffu, 4);  // 4 billion particles promised, 3 carried
  expect_rejected(truth_, {"set-truth", "4294967295 + 1 particles", "carries 72 bytes"});
}

TEST_F(BadSessionMessage, LengthFieldsLargerThanTheMessage) {
  put_le(start_, 24, 0x00ffffffu, 4);  // rig config length beyond the message (but under the cap)
  expect_rejected(start_, {"truncated session message", "rig_config"});
  start_ = bytes_of(encode_session_start(sample_start(true)));
  put_le(start_, 24, 0xffffffffu, 4);
  expect_rejected(start_, {"rig_config", "at most"});
  put_le(end_, 32, 1000, 4);
  expect_rejected(end_, {"truncated", "reason"});
}

TEST_F(BadSessionMessage, InvalidValues) {
  put_le(start_, 16, 0, 8);
  expect_rejected(start_, {"session_id is 0"});
  start_ = bytes_of(encode_session_start(sample_start(true)));
  put_le(start_, 12, 0, 2);
  expect_rejected(start_, {"camera_count = 0"});

  SessionStart twice = sample_start(false);
  twice.info.cameras[1].id = "cam0";
  expect_rejected(bytes_of(encode_session_start(twice)), {"camera 'cam0' is announced twice"});
  SessionStart half = sample_start(false);
  half.info.cameras[0].height = 0;
  expect_rejected(bytes_of(encode_session_start(half)), {"640 x 0"});
  SessionStart nan_pitch = sample_start(false);
  nan_pitch.info.cameras[0].pixel_pitch_um = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(bytes_of(encode_session_start(nan_pitch)), {"pixel_pitch_um", "not a finite number"});
  SessionStart nul = sample_start(false);
  nul.info.rig_config_toml = std::string("a\0b", 3);
  expect_rejected(bytes_of(encode_session_start(nul)), {"rig_config", "NUL"});
  SetTruth inf = sample_set_truth();
  inf.particles.particles_b[0].z = std::numeric_limits<double>::infinity();
  expect_rejected(bytes_of(encode_set_truth(inf)), {"particle.z", "not a finite number"});
}

TEST_F(BadSessionMessage, MultipartSessionMessage) {
  auto parts = one_part(start_);
  parts.emplace_back(4);
  expect_error([&] { decode_stream_message(std::move(parts)); }, ErrorKind::bad_input,
               {"session-start", "wrong part count", "got 2"});
}

TEST(SessionMessages, EncoderRefusesWhatTheLayoutCannotHold) {
  SessionStart no_id = sample_start(false);
  no_id.session_id = 0;
  expect_error([&] { (void)encode_session_start(no_id); }, ErrorKind::bad_input, {"non-zero session_id"});
  SessionStart no_cameras = sample_start(false);
  no_cameras.info.cameras.clear();
  expect_error([&] { (void)encode_session_start(no_cameras); }, ErrorKind::bad_input, {"1..32767 cameras"});
  EXPECT_NE(new_session_id(), 0u);
  EXPECT_NE(new_session_id(), new_session_id());
}

// Randomised damage (deterministic seed) to all three kinds: the decoder accepts or throws
// bad_input with a reason; it never crashes or throws anything else. Run under ASan to catch
// stray reads as well.
TEST(SessionMessages, DamagedMessagesAreRejectedOrDecodedSafely) {
  const std::vector<std::vector<std::byte>> bases = {bytes_of(encode_session_start(sample_start(true))),
                                                     bytes_of(encode_set_truth(sample_set_truth())),
                                                     bytes_of(encode_session_end(sample_end()))};
  std::mt19937_64 rng(20261124);
  auto pick = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
  int accepted = 0, rejected = 0;
  constexpr int kCases = 6000;
  for (int i = 0; i < kCases; ++i) {
    std::vector<std::byte> m = bases[pick(bases.size())];
    switch (pick(5)) {
      case 0:
        for (std::size_t k = 0, n = 1 + pick(4); k < n; ++k) m[pick(m.size())] ^= std::byte(1 + pick(255));
        break;
      case 1: m.resize(pick(m.size())); break;
      case 2:
        for (std::size_t k = 0, n = 1 + pick(64); k < n; ++k) m.push_back(std::byte(pick(256)));
        break;
      case 3: {  // an extreme value anywhere: lengths, counts, sizes
        const std::uint64_t v =
            std::array<std::uint64_t, 7>{0, 1, 0xffff, 0x10000, 0x7fffffff, 0xffffffffull, ~0ull}[pick(7)];
        const std::size_t at = pick(m.size());
        for (std::size_t k = 0; k < 8 && at + k < m.size(); ++k) m[at + k] = std::byte((v >> (8 * k)) & 0xff);
        break;
      }
      default: {  // harmless: a byte inside the last text field or a particle coordinate's low bits
        m[m.size() - 1] = std::byte{'x'};
        break;
      }
    }
    try {
      const StreamMessage decoded = decode_bytes(m);
      EXPECT_FALSE(std::holds_alternative<FrameSet>(decoded)) << "case " << i;
      ++accepted;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      EXPECT_GT(std::string(e.what()).size(), 10u);
      ++rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << i << " threw a non-tomorig exception: " << e.what();
    }
  }
  EXPECT_EQ(accepted + rejected, kCases);
  EXPECT_GT(accepted, 0) << "harmless mutations must still decode";
  EXPECT_GT(rejected, kCases / 2);
}

// Start, truth, sets and end go through a real TCP PUSH/PULL pair in order; receive() skips the
// session messages, receive_message() returns them, and a new session restarts the gap count.
TEST(SessionMessages, TravelInOrderWithTheFrameSets) {
  zmq::context_t context;
  SocketOptions out;
  out.endpoint.address = "tcp://127.0.0.1:*";
  out.timeout = 5s;
  FrameSender sender(context, out);
  SocketOptions in = out;
  in.endpoint = {sender.endpoint(), false, false};
  FrameReceiver receiver(context, in);

  const SessionStart start = sample_start(true);
  ASSERT_TRUE(sender.send(start));
  SetTruth truth = sample_set_truth();
  truth.trigger_index = 1000;  // pattern_set(0) has trigger index 1000
  ASSERT_TRUE(sender.send(truth));
  ASSERT_TRUE(sender.send(pattern_set(0, 2, 32, 16, SampleType::u16)));
  ASSERT_TRUE(sender.send(pattern_set(1, 2, 32, 16, SampleType::u16)));
  SessionEnd end = sample_end();
  end.sets_sent = 2;
  ASSERT_TRUE(sender.send(end));
  EXPECT_EQ(sender.stats().sets_sent, 2u);  // session messages are not sets

  auto next = [&] {
    auto m = receiver.receive_message();
    EXPECT_TRUE(m.has_value());
    return m ? std::move(*m) : StreamMessage{};
  };
  EXPECT_EQ(std::get<SessionStart>(next()).info.cameras.size(), 3u);
  EXPECT_EQ(std::get<SetTruth>(next()).trigger_index, 1000u);
  expect_same_set(std::get<FrameSet>(next()), pattern_set(0, 2, 32, 16, SampleType::u16));
  EXPECT_EQ(std::get<FrameSet>(next()).set_index, 1u);
  EXPECT_EQ(std::get<SessionEnd>(next()).sets_sent, 2u);

  // A second session starting at set 0 after a gap-free first one: no sets counted missing.
  ASSERT_TRUE(sender.send(start));
  ASSERT_TRUE(sender.send(pattern_set(0, 2, 32, 16, SampleType::u16)));
  ASSERT_TRUE(sender.send(pattern_set(2, 2, 32, 16, SampleType::u16)));
  const auto a = receiver.receive();  // the start is skipped
  ASSERT_TRUE(a);
  EXPECT_EQ(a->set_index, 0u);
  ASSERT_TRUE(receiver.receive());
  const ReceiverStats stats = receiver.stats();
  EXPECT_EQ(stats.sets_received, 4u);
  EXPECT_EQ(stats.session_messages, 4u);
  EXPECT_EQ(stats.sets_missing, 1u);  // set 1 of the second session, not the restart at 0
  EXPECT_EQ(stats.rejected_messages, 0u);
}

}  // namespace
}  // namespace tomorig::stream
