// Encode/decode of the wire format: bit-identical round trips, zero copy on both ends, and a
// reasoned refusal of every kind of bad message.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <vector>

#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "stream_test_support.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream {
namespace {
using testing::expect_error;
using testing::expect_same_set;
using testing::pattern_image;
using testing::pattern_set;

// A view with padded rows over a larger buffer, as camera drivers deliver them.
Image strided_copy(const Image& source, std::size_t padding) {
  const std::size_t stride = source.row_bytes() + padding;
  auto buffer = std::make_shared<std::vector<std::byte>>(stride * source.height(), std::byte{0xEE});
  for (int y = 0; y < source.height(); ++y)
    std::memcpy(buffer->data() + y * stride, source.data() + y * source.stride_bytes(), source.row_bytes());
  return Image::view(buffer->data(), source.width(), source.height(), source.type(), stride, buffer);
}

// Sets that exercise the header: several formats, a strided frame, a missing frame.
FrameSet mixed_set() {
  FrameSet set = pattern_set(42, 3, 20, 12, SampleType::u16);
  set.cameras[1].a.image = pattern_image(17, 9, SampleType::u8, 42, 1, 0);
  set.cameras[1].b.image = strided_copy(pattern_image(17, 9, SampleType::u8, 42, 1, 1), 7);
  set.cameras[2].a.image = strided_copy(set.cameras[2].a.image, 6);
  set.cameras[2].b = Frame{};  // lost frame
  set.cameras[0].camera_id = "GVA-serial-0001";
  return set;
}

TEST(WireFormat, RoundTripInMemoryIsBitIdentical) {
  for (SampleType type : {SampleType::u8, SampleType::u16, SampleType::f32}) {
    const FrameSet set = pattern_set(7, 2, 33, 21, type);
    expect_same_set(decode_frame_set(encode_frame_set(set)), set);
  }
  const FrameSet mixed = mixed_set();
  const FrameSet back = decode_frame_set(encode_frame_set(mixed));
  expect_same_set(back, mixed);
  EXPECT_EQ(back.cameras[2].a.image.stride_bytes(), mixed.cameras[2].a.image.stride_bytes());
  EXPECT_FALSE(back.cameras[2].b.present());
  EXPECT_EQ(back.missing_frames(), 1);
}

TEST(WireFormat, HeaderLayoutMatchesTheDocument) {
  const FrameSet set = pattern_set(5, 1, 4, 3, SampleType::u16);
  const auto parts = encode_frame_set(set);
  ASSERT_EQ(parts.size(), 3u);
  // 48 fixed + (2 + "cam0") id table + 2 entries of 40 bytes.
  EXPECT_EQ(parts[0].size(), kFixedHeaderBytes + 6 + 2 * kFrameEntryBytes);
  const auto* h = static_cast<const std::uint8_t*>(parts[0].data());
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(h), 4), "TMRG");
  EXPECT_EQ(h[4] | h[5] << 8, kWireProtocolVersion);
  EXPECT_EQ(h[8], 5);       // set_index, little-endian
  EXPECT_EQ(h[40], 1);      // camera_count
  EXPECT_EQ(h[42], 2);      // frame_count
  const std::uint8_t* entry = h + 48 + 6;
  EXPECT_EQ(entry[3], static_cast<int>(WirePixelFormat::mono16));
  EXPECT_EQ(entry[8], 4);   // width
  EXPECT_EQ(entry[12], 3);  // height
  EXPECT_EQ(entry[32], 24); // byte_count = 4 * 3 * 2
  EXPECT_EQ(parts[1].size(), 24u);
}

// Over TCP the pixels are really copied by the kernel: the round trip must still be exact,
// and camera-sized frames must decode as views into the received parts (no second copy).
// ZeroMQ packs small messages (< 8 KiB) back to back in one receive buffer, at any
// alignment; those are copied into aligned Images instead, which the mixed set exercises.
TEST(WireFormat, TcpRoundTripIsBitIdenticalAndDecodesInPlace) {
  zmq::context_t context;
  zmq::socket_t pull(context, zmq::socket_type::pull);
  pull.bind("tcp://127.0.0.1:*");
  zmq::socket_t push(context, zmq::socket_type::push);
  push.connect(pull.get(zmq::sockopt::last_endpoint));

  const FrameSet small = mixed_set();
  zmq::send_multipart(push, encode_frame_set(small));
  FrameSet large = pattern_set(43, 2, 160, 80, SampleType::u16);
  large.cameras[0].b.image = strided_copy(large.cameras[0].b.image, 24);
  large.cameras[1].a.image = pattern_image(200, 90, SampleType::u8, 43, 1, 0);
  zmq::send_multipart(push, encode_frame_set(large));

  std::vector<zmq::message_t> parts;
  ASSERT_TRUE(zmq::recv_multipart(pull, std::back_inserter(parts)));
  expect_same_set(decode_frame_set(std::move(parts)), small);

  parts.clear();
  ASSERT_TRUE(zmq::recv_multipart(pull, std::back_inserter(parts)));
  std::vector<std::pair<const std::byte*, std::size_t>> ranges;
  for (auto& p : parts) ranges.emplace_back(static_cast<const std::byte*>(p.data()), p.size());
  const FrameSet back = decode_frame_set(std::move(parts));
  expect_same_set(back, large);
  EXPECT_EQ(back.cameras[0].b.image.stride_bytes(), 160u * 2 + 24);
  for (std::size_t c = 0; c < back.cameras.size(); ++c)
    for (Exposure e : {Exposure::A, Exposure::B}) {
      const Image& im = back.cameras[c][e].image;
      const auto [begin, size] = ranges[1 + 2 * c + static_cast<int>(e)];
      EXPECT_EQ(im.data(), begin) << "camera " << c << " was copied, not viewed in place";
      EXPECT_EQ(wire_frame_bytes(im), size);
    }
}

// The sender hands ZeroMQ the camera buffer itself. Its lease must stay held until the
// receiver is done with it (over inproc the receiver gets the very same memory).
TEST(WireFormat, SenderBufferIsLeasedUntilTheMessageIsDone) {
  zmq::context_t context;
  SocketOptions out;
  out.endpoint.address = "inproc://lease-test";
  FrameSender sender(context, out);
  SocketOptions in = out;
  in.endpoint.bind = false;
  FrameReceiver receiver(context, in);

  std::vector<std::uint16_t> camera_buffer(64 * 48, 0x1234);
  std::atomic<bool> released{false};
  FrameSet set = pattern_set(0, 1, 64, 48, SampleType::u16);
  set.cameras[0].a.image = Image::view(camera_buffer.data(), 64, 48, SampleType::u16, 0,
                                       std::shared_ptr<void>(camera_buffer.data(), [&](void*) { released = true; }));
  ASSERT_TRUE(sender.send(set));
  set = FrameSet{};  // the producer lets go of its reference at once
  EXPECT_FALSE(released) << "the buffer was released while ZeroMQ still queued it";

  auto got = receiver.receive();
  ASSERT_TRUE(got);
  const Image& im = got->cameras[0].a.image;
  EXPECT_EQ(static_cast<const void*>(im.data()), static_cast<const void*>(camera_buffer.data()))
      << "inproc delivery should hand over the sender's buffer itself";
  EXPECT_EQ(im.at<std::uint16_t>(63, 47), 0x1234);
  EXPECT_FALSE(released);
  got.reset();
  EXPECT_TRUE(released) << "the last reference is gone but the lease was not released";
}

TEST(WireFormat, LeaseIsReleasedAfterATcpSend) {
  zmq::context_t context;
  SocketOptions out;
  out.endpoint.address = "tcp://127.0.0.1:*";
  FrameSender sender(context, out);
  SocketOptions in = out;
  in.endpoint = {sender.endpoint(), false, false};
  FrameReceiver receiver(context, in);

  std::vector<std::uint16_t> camera_buffer(256 * 256, 7);
  std::atomic<bool> released{false};
  FrameSet set = pattern_set(0, 1, 256, 256, SampleType::u16);
  set.cameras[0].b.image =
      Image::view(camera_buffer.data(), 256, 256, SampleType::u16, 0,
                  std::shared_ptr<void>(camera_buffer.data(), [&](void*) { released = true; released.notify_all(); }));
  ASSERT_TRUE(sender.send(set));
  set = FrameSet{};
  const auto got = receiver.receive();
  ASSERT_TRUE(got);
  EXPECT_NE(static_cast<const void*>(got->cameras[0].b.image.data()), static_cast<const void*>(camera_buffer.data()));
  EXPECT_EQ(got->cameras[0].b.image.at<std::uint16_t>(255, 255), 7);
  released.wait(false);  // ZeroMQ's I/O thread releases it once written; a leak would hang here
  EXPECT_TRUE(released);
}

// ---- bad messages -----------------------------------------------------------------------

std::vector<std::byte> header_bytes(const FrameSet& set) {
  const auto parts = encode_frame_set(set);
  const auto* p = static_cast<const std::byte*>(parts[0].data());
  return {p, p + parts[0].size()};
}

// A valid message for `set` whose header is replaced by `header`.
std::vector<zmq::message_t> with_header(const FrameSet& set, const std::vector<std::byte>& header) {
  auto parts = encode_frame_set(set);
  parts[0] = zmq::message_t(header.data(), header.size());
  return parts;
}

void put_u16(std::vector<std::byte>& h, std::size_t at, std::uint16_t v) {
  h[at] = std::byte(v & 0xff);
  h[at + 1] = std::byte(v >> 8);
}
void put_u32(std::vector<std::byte>& h, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) h[at + i] = std::byte((v >> (8 * i)) & 0xff);
}

class BadMessage : public ::testing::Test {
 protected:
  void expect_rejected(std::vector<zmq::message_t> parts, const std::vector<std::string>& words) {
    expect_error([&] { decode_frame_set(std::move(parts)); }, ErrorKind::bad_input, words);
  }
  void expect_rejected(const std::vector<std::byte>& header, const std::vector<std::string>& words) {
    expect_rejected(with_header(set_, header), words);
  }
  FrameSet set_ = pattern_set(3, 2, 8, 6, SampleType::u16);  // id table: 2 x (2 + 4) bytes
  std::vector<std::byte> header_ = header_bytes(set_);
  const std::size_t entries_ = kFixedHeaderBytes + 12;
};

TEST_F(BadMessage, EmptyMessage) { expect_rejected(std::vector<zmq::message_t>{}, {"empty"}); }

TEST_F(BadMessage, WrongMagic) {
  header_[0] = std::byte{'X'};
  expect_rejected(header_, {"magic", "TMRG"});
}

TEST_F(BadMessage, OldProtocolVersionNamesBothVersions) {
  put_u16(header_, 4, 0);
  expect_rejected(header_, {"version 0", "version " + std::to_string(kWireProtocolVersion)});
  put_u16(header_, 4, kWireProtocolVersion + 1);
  expect_rejected(header_, {"version " + std::to_string(kWireProtocolVersion + 1)});
}

TEST_F(BadMessage, VersionIsCheckedBeforeTheRestOfTheLayout) {
  // An old peer's header may have another length; the version error still comes first.
  std::vector<std::byte> old(header_.begin(), header_.begin() + 20);
  put_u16(old, 4, 0);
  expect_rejected(old, {"version 0"});
}

TEST_F(BadMessage, UnknownMessageType) {
  put_u16(header_, 6, 9);
  expect_rejected(header_, {"message type 9"});
}

TEST_F(BadMessage, TruncatedHeaders) {
  for (std::size_t n : {0u, 2u, 5u, 30u, 47u}) {
    const std::vector<std::byte> cut(header_.begin(), header_.begin() + n);
    expect_rejected(cut, {"truncated"});
  }
  const std::vector<std::byte> cut(header_.begin(), header_.end() - 1);
  expect_rejected(cut, {"header is", "truncated or corrupt"});
}

TEST_F(BadMessage, FrameCountNotTwicePerCamera) {
  put_u16(header_, 42, 3);
  expect_rejected(header_, {"3 frames for 2 cameras"});
}

TEST_F(BadMessage, CountsThatPromiseMoreThanTheHeaderHolds) {
  put_u16(header_, 40, 60000);
  put_u16(header_, 42, 0);  // frame_count is 16 bits: 2 x 60000 cannot even be declared
  expect_rejected(header_, {"frames for 60000 cameras"});
  header_ = header_bytes(set_);
  put_u32(header_, 44, 0xffffffffu);
  expect_rejected(header_, {"truncated or corrupt"});
}

TEST_F(BadMessage, WrongPartCount) {
  auto parts = encode_frame_set(set_);
  parts.pop_back();
  expect_rejected(std::move(parts), {"wrong part count", "needs 5 parts, got 4"});
  auto more = encode_frame_set(set_);
  more.emplace_back(3);
  expect_rejected(std::move(more), {"wrong part count", "got 6"});
}

TEST_F(BadMessage, PixelPartSizeMismatch) {
  auto parts = encode_frame_set(set_);
  parts[3] = zmq::message_t(8 * 6 * 2 - 1);
  expect_rejected(std::move(parts), {"size mismatch", "camera 1", "declares 96 bytes", "holds 95"});
}

TEST_F(BadMessage, CameraIdTableInconsistent) {
  put_u16(header_, kFixedHeaderBytes, 200);  // first id claims 200 bytes
  expect_rejected(header_, {"id table"});
  header_ = header_bytes(set_);
  header_[kFixedHeaderBytes + 2 + 6 + 3] = std::byte{'0'};  // "cam1" -> "cam0"
  expect_rejected(header_, {"camera 'cam0' twice"});
}

TEST_F(BadMessage, BadFrameEntries) {
  auto entry = [&](int i, int field) { return entries_ + i * kFrameEntryBytes + field; };
  header_[entry(0, 0)] = std::byte{5};
  expect_rejected(header_, {"refers to camera 5"});

  header_ = header_bytes(set_);
  header_[entry(1, 2)] = std::byte{2};
  expect_rejected(header_, {"exposure code 2"});

  header_ = header_bytes(set_);
  header_[entry(1, 2)] = std::byte{0};  // two A frames for camera 0
  expect_rejected(header_, {"repeats"});

  header_ = header_bytes(set_);
  header_[entry(2, 3)] = std::byte{77};
  expect_rejected(header_, {"pixel format code 77"});

  header_ = header_bytes(set_);
  header_[entry(0, 4)] = std::byte{0x81};
  expect_rejected(header_, {"flag bits"});

  header_ = header_bytes(set_);
  put_u32(header_, entry(0, 8), 0);
  expect_rejected(header_, {"size 0 x 6"});

  header_ = header_bytes(set_);
  put_u32(header_, entry(0, 12), 0xffffffffu);
  expect_rejected(header_, {"width and height must be"});

  header_ = header_bytes(set_);
  put_u32(header_, entry(0, 16), 3);  // stride below a row
  expect_rejected(header_, {"stride of 3 bytes"});

  header_ = header_bytes(set_);
  put_u32(header_, entry(0, 16), 17);  // rows would start at odd addresses for 16-bit samples
  expect_rejected(header_, {"stride of 17 bytes, not a multiple"});

  header_ = header_bytes(set_);
  put_u32(header_, entry(0, 32), 1000);
  expect_rejected(header_, {"declares 1000 bytes", "needs 96"});

  header_ = header_bytes(set_);
  header_[entry(0, 4)] = std::byte{0};  // marked missing but has pixels
  expect_rejected(header_, {"marked missing"});
}

// Issue 14, defect 5: ids that cannot name a camera (a path, a non-UTF-8 byte, a NUL, an escape
// sequence) are refused by the decoder with the id escaped, never stored or echoed raw.
TEST_F(BadMessage, CameraIdsThatAreNotValidIds) {
  using namespace std::string_literals;
  for (const std::string& id : {"a/b"s, ".."s, "\xff"s, "a\0b"s, "cam\x1b[2J"s}) {
    FrameSet set = set_;
    set.cameras[1].camera_id = id;
    try {
      decode_frame_set(encode_frame_set(set));
      ADD_FAILURE() << "accepted camera id " << ::testing::PrintToString(id);
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      const std::string message = e.what();
      EXPECT_NE(message.find("wire header: camera id"), std::string::npos) << message;
      EXPECT_NE(message.find("is not allowed"), std::string::npos) << message;
      EXPECT_EQ(message.find('\x1b'), std::string::npos) << "raw escape byte in the message";
    }
  }
}

TEST_F(BadMessage, ReservedBytesMustBeZero) {
  header_[entries_ + 5] = std::byte{1};
  expect_rejected(header_, {"reserved"});
}

}  // namespace
}  // namespace tomorig::stream

namespace tomorig::stream {
namespace {

// A free-running camera's frame crosses the stream still marked as not of its set's event.
TEST(WireFormat, AnUnsynchronisedFrameStaysFlagged) {
  FrameSet set = pattern_set(3, 2, 8, 6, SampleType::u16);
  set.cameras[1].b.synchronised = false;
  ASSERT_FALSE(set.complete());
  const FrameSet back = decode_frame_set(encode_frame_set(set));
  expect_same_set(back, set);
  EXPECT_TRUE(back.cameras[1].b.present());
  EXPECT_FALSE(back.cameras[1].b.synchronised);
  EXPECT_TRUE(back.cameras[1].a.synchronised);
  EXPECT_FALSE(back.complete());
}

}  // namespace
}  // namespace tomorig::stream
