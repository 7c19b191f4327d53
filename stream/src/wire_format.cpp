#include "tomorig/stream/wire_format.h"

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_set>

#include <fmt/format.h>

#include "byte_io.h"
#include "tomorig/core/camera_id.h"
#include "tomorig/core/error.h"
#include "wire_preamble.h"

namespace tomorig::stream {
namespace {

using detail::ByteReader;
using detail::ByteWriter;

constexpr std::uint8_t kFlagPresent = 0x01;
// A free-running camera's frame: present, but not exposed by this set's trigger event.
constexpr std::uint8_t kFlagUnsynchronised = 0x02;

WirePixelFormat wire_format_of(SampleType type) {
  switch (type) {
    case SampleType::u8: return WirePixelFormat::mono8;
    case SampleType::u16: return WirePixelFormat::mono16;
    case SampleType::f32: return WirePixelFormat::float32;
  }
  return WirePixelFormat::none;
}

// Sample type a wire pixel format is held in; false for an unknown code.
bool sample_type_of(std::uint8_t code, SampleType& type) {
  switch (static_cast<WirePixelFormat>(code)) {
    case WirePixelFormat::mono8: type = SampleType::u8; return true;
    case WirePixelFormat::mono12:
    case WirePixelFormat::mono16: type = SampleType::u16; return true;
    case WirePixelFormat::float32: type = SampleType::f32; return true;
    case WirePixelFormat::none: break;
  }
  return false;
}

// ZeroMQ calls this once it no longer needs a pixel part; dropping the Image copy releases
// its lease (camera buffer, file buffer, or the sender's allocation).
void release_image(void* /*data*/, void* hint) { std::unique_ptr<Image> owned(static_cast<Image*>(hint)); }

zmq::message_t zero_copy_part(const Image& image) {
  if (image.empty()) return zmq::message_t();
  auto keeper = std::make_unique<Image>(image);
  // ZeroMQ only reads the buffer; its API takes a non-const pointer.
  zmq::message_t part(const_cast<std::byte*>(keeper->data()), wire_frame_bytes(image), &release_image,
                      keeper.get());
  keeper.release();  // now owned by the message, freed in release_image
  return part;
}

void write_frame_entry(ByteWriter& w, std::uint16_t camera, Exposure exposure, const Frame& frame) {
  const Image& im = frame.image;
  w.u16(camera);
  w.u8(static_cast<std::uint8_t>(exposure));
  w.u8(static_cast<std::uint8_t>(im.empty() ? WirePixelFormat::none : wire_format_of(im.type())));
  w.u8(im.empty() ? 0 : static_cast<std::uint8_t>(kFlagPresent | (frame.synchronised ? 0 : kFlagUnsynchronised)));
  w.u8(0);
  w.u16(0);
  w.u32(im.empty() ? 0 : static_cast<std::uint32_t>(im.width()));
  w.u32(im.empty() ? 0 : static_cast<std::uint32_t>(im.height()));
  w.u64(im.empty() ? 0 : im.stride_bytes());
  w.i64(frame.timestamp_ns);
  w.u64(im.empty() ? 0 : wire_frame_bytes(im));
}

struct FrameEntry {
  std::uint16_t camera = 0;
  std::uint8_t exposure = 0;
  std::uint8_t format = 0;
  std::uint8_t flags = 0;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint64_t stride = 0;
  std::int64_t timestamp_ns = 0;
  std::uint64_t byte_count = 0;
};

FrameEntry read_frame_entry(ByteReader& r) {
  FrameEntry e;
  e.camera = r.u16("frame.camera");
  e.exposure = r.u8("frame.exposure");
  e.format = r.u8("frame.pixel_format");
  e.flags = r.u8("frame.flags");
  if (r.u8("frame.reserved8") != 0 || r.u16("frame.reserved16") != 0)
    throw bad_input("wire header frame entry has non-zero reserved bytes (a newer or corrupt sender)");
  e.width = r.u32("frame.width");
  e.height = r.u32("frame.height");
  e.stride = r.u64("frame.stride");
  e.timestamp_ns = r.i64("frame.timestamp_ns");
  e.byte_count = r.u64("frame.byte_count");
  return e;
}

std::string frame_name(std::size_t index, const FrameEntry& e) {
  return fmt::format("frame entry {} (camera {}, exposure {})", index, e.camera, e.exposure == 0 ? "A" : "B");
}

// Checks one entry against its part and wraps the part as an Image (zero-copy when the
// part's memory is aligned for the sample type, which ZeroMQ gives every part over 33 bytes).
Image image_from_part(std::size_t index, const FrameEntry& e, zmq::message_t&& part) {
  if ((e.flags & kFlagPresent) == 0) {
    if (e.format != 0 || e.width != 0 || e.height != 0 || e.stride != 0 || e.byte_count != 0 || part.size() != 0)
      throw bad_input(frame_name(index, e) + " is marked missing but declares pixels or has a non-empty part");
    return {};
  }
  SampleType type{};
  if (!sample_type_of(e.format, type))
    throw bad_input(fmt::format("{} has unknown pixel format code {} (known: 1 Mono8, 2 Mono12, 3 Mono16, 4 Float32)",
                                frame_name(index, e), e.format));
  if (e.width == 0 || e.height == 0 || e.width > kMaxImageSide || e.height > kMaxImageSide)
    throw bad_input(fmt::format("{} declares size {} x {}; width and height must be 1..{}", frame_name(index, e),
                                e.width, e.height, kMaxImageSide));
  const std::uint64_t row_bytes = std::uint64_t{e.width} * bytes_per_sample(type);
  if (e.stride < row_bytes || e.stride > (std::uint64_t{1} << 32))
    throw bad_input(fmt::format("{} declares a row stride of {} bytes; a {}-pixel row needs {}..2^32 bytes",
                                frame_name(index, e), e.stride, e.width, row_bytes));
  if (e.stride % bytes_per_sample(type) != 0)
    throw bad_input(fmt::format("{} declares a row stride of {} bytes, not a multiple of its {}-byte samples",
                                frame_name(index, e), e.stride, bytes_per_sample(type)));
  const std::uint64_t expected = e.stride * (e.height - 1) + row_bytes;  // < 2^49: no overflow
  if (e.byte_count != expected)
    throw bad_input(fmt::format("{} declares {} bytes but {} x {} with stride {} needs {}", frame_name(index, e),
                                e.byte_count, e.width, e.height, e.stride, expected));
  if (part.size() != e.byte_count)
    throw bad_input(fmt::format("size mismatch: {} declares {} bytes but its part holds {}", frame_name(index, e),
                                e.byte_count, part.size()));

  auto lease = std::make_shared<zmq::message_t>(std::move(part));
  void* data = lease->data();
  const int w = static_cast<int>(e.width), h = static_cast<int>(e.height);
  if (reinterpret_cast<std::uintptr_t>(data) % bytes_per_sample(type) == 0)
    return Image::view(data, w, h, type, e.stride, std::move(lease));
  // A misaligned part (only tiny ones live inside the message struct) is copied row by row.
  return Image::view(data, w, h, type, e.stride).clone();
}

}  // namespace

std::size_t wire_frame_bytes(const Image& image) {
  if (image.empty()) return 0;
  return image.stride_bytes() * static_cast<std::size_t>(image.height() - 1) + image.row_bytes();
}

std::vector<zmq::message_t> encode_frame_set(const FrameSet& set) {
  if (set.cameras.size() > 0x7fff)
    throw bad_input(fmt::format("a frame set with {} cameras cannot be sent; the wire format allows 32767",
                                set.cameras.size()));
  std::size_t table_bytes = 0;
  for (const auto& cam : set.cameras) {
    if (cam.camera_id.size() > 0xffff)
      throw bad_input("camera id '" + cam.camera_id.substr(0, 32) + "...' is longer than 65535 bytes");
    table_bytes += 2 + cam.camera_id.size();
  }
  const std::size_t frame_count = 2 * set.cameras.size();

  std::vector<std::byte> header;
  header.reserve(kFixedHeaderBytes + table_bytes + frame_count * kFrameEntryBytes);
  ByteWriter w(header);
  detail::write_preamble(w, MessageType::frame_set);
  w.u64(set.set_index);
  w.u64(set.trigger_index);
  w.i64(set.trigger_timestamp_ns);
  w.i64(set.dt_ns);
  w.u16(static_cast<std::uint16_t>(set.cameras.size()));
  w.u16(static_cast<std::uint16_t>(frame_count));
  w.u32(static_cast<std::uint32_t>(table_bytes));
  for (const auto& cam : set.cameras) {
    w.u16(static_cast<std::uint16_t>(cam.camera_id.size()));
    w.bytes(cam.camera_id.data(), cam.camera_id.size());
  }
  for (std::size_t c = 0; c < set.cameras.size(); ++c) {
    write_frame_entry(w, static_cast<std::uint16_t>(c), Exposure::A, set.cameras[c].a);
    write_frame_entry(w, static_cast<std::uint16_t>(c), Exposure::B, set.cameras[c].b);
  }

  std::vector<zmq::message_t> parts;
  parts.reserve(1 + frame_count);
  parts.emplace_back(header.data(), header.size());
  for (const auto& cam : set.cameras) {
    parts.push_back(zero_copy_part(cam.a.image));
    parts.push_back(zero_copy_part(cam.b.image));
  }
  return parts;
}

FrameSet decode_frame_set(std::vector<zmq::message_t>&& parts) {
  if (parts.empty()) throw bad_input("empty wire message: expected a frame-set header part");
  const zmq::message_t& head = parts[0];
  ByteReader r(std::span<const std::byte>(static_cast<const std::byte*>(head.data()), head.size()));

  const std::uint16_t type = detail::read_preamble(r);
  if (type != static_cast<std::uint16_t>(MessageType::frame_set))
    throw bad_input(fmt::format("message type {} ({}) is not a frame set (type {})", type,
                                detail::message_type_name(type), static_cast<int>(MessageType::frame_set)));

  FrameSet set;
  set.set_index = r.u64("set_index");
  set.trigger_index = r.u64("trigger_index");
  set.trigger_timestamp_ns = r.i64("trigger_timestamp_ns");
  set.dt_ns = r.i64("dt_ns");
  const std::uint16_t camera_count = r.u16("camera_count");
  const std::uint16_t frame_count = r.u16("frame_count");
  const std::uint32_t table_bytes = r.u32("string_table_bytes");
  if (frame_count != 2u * camera_count)
    throw bad_input(fmt::format("wire header lists {} frames for {} cameras; a frame set has exactly 2 per camera",
                                frame_count, camera_count));
  const std::uint64_t header_bytes =
      kFixedHeaderBytes + std::uint64_t{table_bytes} + std::uint64_t{frame_count} * kFrameEntryBytes;
  if (header_bytes != head.size())
    throw bad_input(fmt::format("wire header is {} bytes but its counts ({} cameras, {}-byte id table) imply {}; "
                                "the header is truncated or corrupt",
                                head.size(), camera_count, table_bytes, header_bytes));
  if (parts.size() != 1u + frame_count)
    throw bad_input(fmt::format("wrong part count: the header lists {} frames, so the message needs {} parts, got {}",
                                frame_count, 1 + frame_count, parts.size()));

  set.cameras.resize(camera_count);
  const std::size_t table_start = r.offset();
  for (auto& cam : set.cameras) {
    const std::uint16_t length = r.u16("camera_id.length");
    if (r.offset() + length > table_start + table_bytes)
      throw bad_input("camera id runs past the end of the id table");
    cam.camera_id = r.string(length, "camera_id");
    require_valid_camera_id(cam.camera_id, "wire header");  // UTF-8, no '/', NUL or escapes (core/camera_id.h)
  }
  if (r.offset() != table_start + table_bytes)
    throw bad_input(fmt::format("camera id table declares {} bytes but its ids fill {}", table_bytes,
                                r.offset() - table_start));
  // A set may declare 32767 cameras: a pairwise comparison would take seconds for one message.
  std::unordered_set<std::string_view> ids;
  ids.reserve(set.cameras.size());
  for (const auto& cam : set.cameras)
    if (!ids.insert(cam.camera_id).second)
      throw bad_input("wire header names camera '" + cam.camera_id + "' twice");

  std::vector<bool> seen(frame_count, false);
  for (std::size_t i = 0; i < frame_count; ++i) {
    const FrameEntry e = read_frame_entry(r);
    if (e.camera >= camera_count)
      throw bad_input(fmt::format("{} refers to camera {} but the header has {}", frame_name(i, e), e.camera,
                                  camera_count));
    if (e.exposure > 1)
      throw bad_input(fmt::format("frame entry {} has exposure code {}; expected 0 (A) or 1 (B)", i, e.exposure));
    if ((e.flags & ~(kFlagPresent | kFlagUnsynchronised)) != 0)
      throw bad_input(fmt::format("{} has unknown flag bits 0x{:02x}", frame_name(i, e), e.flags));
    const std::size_t slot = 2u * e.camera + e.exposure;
    if (seen[slot]) throw bad_input(frame_name(i, e) + " repeats a frame already in the header");
    seen[slot] = true;
    Frame& frame = set.cameras[e.camera][static_cast<Exposure>(e.exposure)];
    frame.timestamp_ns = e.timestamp_ns;
    frame.synchronised = (e.flags & kFlagUnsynchronised) == 0;
    frame.image = image_from_part(i, e, std::move(parts[1 + i]));
  }
  return set;
}

}  // namespace tomorig::stream
