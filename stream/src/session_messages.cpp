#include "tomorig/stream/session_messages.h"

#include <chrono>
#include <cmath>
#include <random>
#include <set>
#include <span>

#include <fmt/format.h>

#include "byte_io.h"
#include "tomorig/core/error.h"
#include "wire_preamble.h"

namespace tomorig::stream {
namespace {

using detail::ByteReader;
using detail::ByteWriter;

constexpr std::uint16_t kFlagTruth = 0x0001;
// Longest text field (rig config, version, reason, ...): far above any rig file, far below
// what would make a lying length field costly.
constexpr std::uint32_t kMaxTextBytes = 16u << 20;
constexpr std::size_t kParticleBytes = 3 * 8;

// ---- encoding ---------------------------------------------------------------------------------

void text32(ByteWriter& w, const std::string& text, const char* field) {
  if (text.size() > kMaxTextBytes)
    throw bad_input(fmt::format("session message field '{}' is {} bytes; the wire format allows {}", field,
                                text.size(), kMaxTextBytes));
  w.u32(static_cast<std::uint32_t>(text.size()));
  w.bytes(text.data(), text.size());
}

void text16(ByteWriter& w, const std::string& text, const char* field) {
  if (text.size() > 0xffff)
    throw bad_input(fmt::format("session message field '{}' ('{}...') is longer than 65535 bytes", field,
                                text.substr(0, 32)));
  w.u16(static_cast<std::uint16_t>(text.size()));
  w.bytes(text.data(), text.size());
}

WirePixelFormat wire_code(PixelFormat format) {
  switch (format) {
    case PixelFormat::Mono8: return WirePixelFormat::mono8;
    case PixelFormat::Mono12: return WirePixelFormat::mono12;
    case PixelFormat::Mono16: return WirePixelFormat::mono16;
  }
  return WirePixelFormat::none;
}

void check_id(std::uint64_t session_id) {
  if (session_id == 0) throw bad_input("a session message needs a non-zero session_id (see new_session_id())");
}

zmq::message_t to_message(const std::vector<std::byte>& bytes) { return zmq::message_t(bytes.data(), bytes.size()); }

void write_truth(ByteWriter& w, const storage::SessionTruth& truth) {
  text32(w, truth.case_name, "truth.case");
  text32(w, truth.flow_name, "truth.flow");
  text32(w, truth.flow_parameters, "truth.flow_parameters");
  w.u64(truth.seed);
  w.f64(truth.ppp);
  if (truth.cameras.size() > 0x7fff)
    throw bad_input(fmt::format("truth for {} cameras cannot be sent; the wire format allows 32767",
                                truth.cameras.size()));
  w.u16(static_cast<std::uint16_t>(truth.cameras.size()));
  w.u16(0);
  for (const auto& c : truth.cameras) {
    text16(w, c.id, "truth camera id");
    text16(w, c.model, "truth camera model");
    w.u32(static_cast<std::uint32_t>(c.width));
    w.u32(static_cast<std::uint32_t>(c.height));
    for (double v : c.K) w.f64(v);
    for (double v : c.R) w.f64(v);
    for (double v : {c.t.x, c.t.y, c.t.z}) w.f64(v);
  }
}

// ---- decoding ---------------------------------------------------------------------------------

[[noreturn]] void reject(const char* message, const std::string& why) {
  throw bad_input(fmt::format("{} message: {}", message, why));
}

std::string read_text(ByteReader& r, std::size_t length, const char* message, const char* field) {
  std::string text = r.string(length, field);
  if (text.find('\0') != std::string::npos) reject(message, fmt::format("field '{}' contains a NUL byte", field));
  return text;
}

std::string text32(ByteReader& r, const char* message, const char* field) {
  const std::uint32_t length = r.u32(field);
  if (length > kMaxTextBytes)
    reject(message, fmt::format("field '{}' declares {} bytes; at most {} are allowed", field, length, kMaxTextBytes));
  return read_text(r, length, message, field);
}

std::string text16(ByteReader& r, const char* message, const char* field) {
  return read_text(r, r.u16(field), message, field);
}

double finite(ByteReader& r, const char* message, const char* field) {
  const double v = r.f64(field);
  if (!std::isfinite(v)) reject(message, fmt::format("field '{}' is not a finite number", field));
  return v;
}

int image_side(ByteReader& r, const char* message, const char* field) {
  const std::uint32_t v = r.u32(field);
  if (v > kMaxImageSide) reject(message, fmt::format("{} = {} is above {}", field, v, kMaxImageSide));
  return static_cast<int>(v);
}

void reserved(ByteReader& r, int bytes, const char* message) {
  std::uint64_t v = 0;
  if (bytes == 1) v = r.u8("reserved");
  if (bytes == 2) v = r.u16("reserved");
  if (bytes == 4) v = r.u32("reserved");
  if (v != 0) reject(message, "non-zero reserved bytes (a newer or corrupt sender)");
}

// Bytes 8-15 after the preamble: format version, then the type's own 8 bytes; the reader is
// left at the session id.
void read_session_version(ByteReader& r, const char* message) {
  const std::uint16_t version = r.u16("session_format_version");
  if (version != kSessionFormatVersion)
    reject(message, fmt::format("the peer sends session format version {} but this program reads version {}; run "
                                "the same tomorig release on both ends",
                                version, kSessionFormatVersion));
}

std::uint64_t read_session_id(ByteReader& r, const char* message) {
  const std::uint64_t id = r.u64("session_id");
  if (id == 0) reject(message, "session_id is 0");
  return id;
}

void expect_end(const ByteReader& r, const char* message) {
  if (r.remaining() != 0)
    reject(message, fmt::format("{} bytes follow the last field (at offset {}); the message is corrupt",
                                r.remaining(), r.offset()));
}

storage::SessionCamera read_camera(ByteReader& r, const char* message) {
  storage::SessionCamera cam;
  cam.id = text16(r, message, "camera.id");
  if (cam.id.empty()) reject(message, "a camera has an empty id");
  cam.width = image_side(r, message, "camera.width");
  cam.height = image_side(r, message, "camera.height");
  if ((cam.width == 0) != (cam.height == 0))
    reject(message, fmt::format("camera '{}' is {} x {}: width and height are both known or both 0", cam.id,
                                cam.width, cam.height));
  const std::uint8_t format = r.u8("camera.pixel_format");
  switch (static_cast<WirePixelFormat>(format)) {
    case WirePixelFormat::mono8: cam.pixel_format = PixelFormat::Mono8; break;
    case WirePixelFormat::mono12: cam.pixel_format = PixelFormat::Mono12; break;
    case WirePixelFormat::mono16: cam.pixel_format = PixelFormat::Mono16; break;
    default:
      reject(message, fmt::format("camera '{}' has pixel format code {} (known: 1 Mono8, 2 Mono12, 3 Mono16)", cam.id,
                                  format));
  }
  reserved(r, 1, message);
  reserved(r, 2, message);
  cam.pixel_pitch_um = finite(r, message, "camera.pixel_pitch_um");
  if (cam.pixel_pitch_um < 0) reject(message, fmt::format("camera '{}' has a negative pixel pitch", cam.id));
  return cam;
}

storage::SessionTruth read_truth(ByteReader& r, const char* message) {
  storage::SessionTruth truth;
  truth.case_name = text32(r, message, "truth.case");
  truth.flow_name = text32(r, message, "truth.flow");
  truth.flow_parameters = text32(r, message, "truth.flow_parameters");
  truth.seed = r.u64("truth.seed");
  truth.ppp = finite(r, message, "truth.ppp");
  const std::uint16_t count = r.u16("truth.camera_count");
  reserved(r, 2, message);
  std::set<std::string> ids;
  for (std::uint16_t i = 0; i < count; ++i) {
    storage::TruthCamera c;
    c.id = text16(r, message, "truth.camera.id");
    if (c.id.empty() || !ids.insert(c.id).second)
      reject(message, fmt::format("truth camera {} has an empty or repeated id '{}'", i, c.id));
    c.model = text16(r, message, "truth.camera.model");
    if (c.model.empty()) reject(message, fmt::format("truth camera '{}' has no model name", c.id));
    c.width = image_side(r, message, "truth.camera.width");
    c.height = image_side(r, message, "truth.camera.height");
    for (double& v : c.K) v = finite(r, message, "truth.camera.K");
    for (double& v : c.R) v = finite(r, message, "truth.camera.R");
    c.t.x = finite(r, message, "truth.camera.t");
    c.t.y = finite(r, message, "truth.camera.t");
    c.t.z = finite(r, message, "truth.camera.t");
    truth.cameras.push_back(std::move(c));
  }
  return truth;
}

ByteReader single_part_reader(const std::vector<zmq::message_t>& parts, const char* message) {
  if (parts.size() != 1)
    reject(message, fmt::format("wrong part count: a session message is one part, got {}", parts.size()));
  return ByteReader(std::span<const std::byte>(static_cast<const std::byte*>(parts[0].data()), parts[0].size()),
                    "session message");
}

SessionStart decode_start(ByteReader& r) {
  const char* message = "session-start";
  read_session_version(r, message);
  const std::uint16_t flags = r.u16("flags");
  if ((flags & ~kFlagTruth) != 0) reject(message, fmt::format("unknown flag bits 0x{:04x}", flags & ~kFlagTruth));
  const std::uint16_t camera_count = r.u16("camera_count");
  if (camera_count == 0 || camera_count > 0x7fff)
    reject(message, fmt::format("camera_count = {}; a session has 1..32767 cameras", camera_count));
  reserved(r, 2, message);
  SessionStart start;
  start.session_id = read_session_id(r, message);
  start.info.rig_config_toml = text32(r, message, "rig_config");
  start.info.software_version = text32(r, message, "software_version");
  start.info.created_utc = text32(r, message, "created_utc");
  std::set<std::string> ids;
  for (std::uint16_t i = 0; i < camera_count; ++i) {
    storage::SessionCamera cam = read_camera(r, message);
    if (!ids.insert(cam.id).second) reject(message, fmt::format("camera '{}' is announced twice", cam.id));
    start.info.cameras.push_back(std::move(cam));
  }
  if ((flags & kFlagTruth) != 0) start.truth = read_truth(r, message);
  expect_end(r, message);
  return start;
}

SetTruth decode_truth(ByteReader& r) {
  const char* message = "set-truth";
  read_session_version(r, message);
  reserved(r, 2, message);
  reserved(r, 4, message);
  SetTruth truth;
  truth.session_id = read_session_id(r, message);
  truth.trigger_index = r.u64("trigger_index");
  const std::uint64_t count_a = r.u32("particles_a_count");
  const std::uint64_t count_b = r.u32("particles_b_count");
  // Checked before anything is allocated: a lying count cannot make the receiver reserve memory.
  if ((count_a + count_b) * kParticleBytes != r.remaining())
    reject(message, fmt::format("it declares {} + {} particles ({} bytes) but carries {} bytes after the header",
                                count_a, count_b, (count_a + count_b) * kParticleBytes, r.remaining()));
  auto read_particles = [&](std::uint64_t count, std::vector<Vec3d>& out) {
    out.resize(count);
    for (Vec3d& p : out) {
      p.x = finite(r, message, "particle.x");
      p.y = finite(r, message, "particle.y");
      p.z = finite(r, message, "particle.z");
    }
  };
  read_particles(count_a, truth.particles.particles_a);
  read_particles(count_b, truth.particles.particles_b);
  return truth;
}

SessionEnd decode_end(ByteReader& r) {
  const char* message = "session-end";
  read_session_version(r, message);
  const std::uint8_t outcome = r.u8("outcome");
  if (outcome > static_cast<std::uint8_t>(SessionOutcome::failed))
    reject(message, fmt::format("outcome code {} is unknown (0 completed, 1 stopped, 2 failed)", outcome));
  reserved(r, 1, message);
  reserved(r, 4, message);
  SessionEnd end;
  end.outcome = static_cast<SessionOutcome>(outcome);
  end.session_id = read_session_id(r, message);
  end.sets_sent = r.u64("sets_sent");
  end.reason = text32(r, message, "reason");
  expect_end(r, message);
  return end;
}

}  // namespace

std::string_view to_string(SessionOutcome outcome) {
  switch (outcome) {
    case SessionOutcome::completed: return "completed";
    case SessionOutcome::stopped: return "stopped";
    case SessionOutcome::failed: return "failed";
  }
  return "unknown";
}

std::uint64_t new_session_id() {
  std::random_device device;
  std::seed_seq seed{device(), device(),
                     static_cast<unsigned>(std::chrono::steady_clock::now().time_since_epoch().count())};
  std::mt19937_64 rng(seed);
  std::uint64_t id = 0;
  while (id == 0) id = rng();
  return id;
}

zmq::message_t encode_session_start(const SessionStart& start) {
  check_id(start.session_id);
  const auto& cameras = start.info.cameras;
  if (cameras.empty() || cameras.size() > 0x7fff)
    throw bad_input(fmt::format("a session start announces 1..32767 cameras, not {}", cameras.size()));
  std::vector<std::byte> bytes;
  ByteWriter w(bytes);
  detail::write_preamble(w, MessageType::session_start);
  w.u16(kSessionFormatVersion);
  w.u16(start.truth ? kFlagTruth : 0);
  w.u16(static_cast<std::uint16_t>(cameras.size()));
  w.u16(0);
  w.u64(start.session_id);
  text32(w, start.info.rig_config_toml, "rig_config");
  text32(w, start.info.software_version, "software_version");
  text32(w, start.info.created_utc, "created_utc");
  for (const auto& cam : cameras) {
    text16(w, cam.id, "camera.id");
    w.u32(static_cast<std::uint32_t>(cam.width));
    w.u32(static_cast<std::uint32_t>(cam.height));
    w.u8(static_cast<std::uint8_t>(wire_code(cam.pixel_format)));
    w.u8(0);
    w.u16(0);
    w.f64(cam.pixel_pitch_um);
  }
  if (start.truth) write_truth(w, *start.truth);
  return to_message(bytes);
}

zmq::message_t encode_set_truth(const SetTruth& truth) {
  check_id(truth.session_id);
  const auto& a = truth.particles.particles_a;
  const auto& b = truth.particles.particles_b;
  if (a.size() > 0xffffffffu || b.size() > 0xffffffffu)
    throw bad_input("a set's truth holds more than 2^32 particles per exposure; the wire format cannot carry it");
  std::vector<std::byte> bytes;
  bytes.reserve(40 + (a.size() + b.size()) * kParticleBytes);
  ByteWriter w(bytes);
  detail::write_preamble(w, MessageType::set_truth);
  w.u16(kSessionFormatVersion);
  w.u16(0);
  w.u32(0);
  w.u64(truth.session_id);
  w.u64(truth.trigger_index);
  w.u32(static_cast<std::uint32_t>(a.size()));
  w.u32(static_cast<std::uint32_t>(b.size()));
  for (const auto* list : {&a, &b})
    for (const Vec3d& p : *list) {
      w.f64(p.x);
      w.f64(p.y);
      w.f64(p.z);
    }
  return to_message(bytes);
}

zmq::message_t encode_session_end(const SessionEnd& end) {
  check_id(end.session_id);
  std::vector<std::byte> bytes;
  ByteWriter w(bytes);
  detail::write_preamble(w, MessageType::session_end);
  w.u16(kSessionFormatVersion);
  w.u8(static_cast<std::uint8_t>(end.outcome));
  w.u8(0);
  w.u32(0);
  w.u64(end.session_id);
  w.u64(end.sets_sent);
  text32(w, end.reason, "reason");
  return to_message(bytes);
}

StreamMessage decode_stream_message(std::vector<zmq::message_t>&& parts) {
  if (parts.empty()) throw bad_input("empty wire message: expected a frame-set or session message");
  std::uint16_t type = 0;
  {
    const zmq::message_t& head = parts[0];
    ByteReader r(std::span<const std::byte>(static_cast<const std::byte*>(head.data()), head.size()));
    type = detail::read_preamble(r);
  }
  switch (static_cast<MessageType>(type)) {
    case MessageType::frame_set: return decode_frame_set(std::move(parts));
    case MessageType::session_start: {
      ByteReader r = single_part_reader(parts, "session-start");
      (void)detail::read_preamble(r);
      return decode_start(r);
    }
    case MessageType::set_truth: {
      ByteReader r = single_part_reader(parts, "set-truth");
      (void)detail::read_preamble(r);
      return decode_truth(r);
    }
    case MessageType::session_end: {
      ByteReader r = single_part_reader(parts, "session-end");
      (void)detail::read_preamble(r);
      return decode_end(r);
    }
  }
  throw bad_input(fmt::format("message type {} is unknown (1 frame set, 2 session start, 3 set truth, 4 session end); "
                              "is the peer a newer tomorig?",
                              type));
}

}  // namespace tomorig::stream
