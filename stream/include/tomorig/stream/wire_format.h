#pragma once
// The tomorig wire format for FrameSets (byte layout: docs/wire-protocol.md).
//
// A FrameSet travels as one multipart ZeroMQ message: part 0 is a small little-endian header
// (magic, protocol version, set/trigger indices, timestamps, Δt, camera ids, one entry per
// frame), then one part per frame holding its pixels. The pixel parts are zero-copy both ways:
// the encoder hands ZeroMQ the Image's own buffer and keeps the Image's lease alive until
// ZeroMQ has sent it; the decoder returns Images that are views into the received message
// parts, each holding its part alive through its lease.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include <zmq.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::stream {

// "TMRG" as the first four bytes of every frame-set header.
inline constexpr std::uint8_t kWireMagic[4] = {'T', 'M', 'R', 'G'};
// Raise on any change of the frame-set layout or meaning; a peer on another version is refused.
// Session messages (tomorig/stream/session_messages.h) were added as new message types with a
// version of their own, so frame sets and older peers stay on version 1.
inline constexpr std::uint16_t kWireProtocolVersion = 1;

// Bytes 6-7 of every message. A receiver older than types 2-4 rejects them by type, counts
// them and goes on with the frame sets.
enum class MessageType : std::uint16_t { frame_set = 1, session_start = 2, set_truth = 3, session_end = 4 };

// Pixel format codes in a frame entry (0 marks a missing frame).
enum class WirePixelFormat : std::uint8_t { none = 0, mono8 = 1, mono12 = 2, mono16 = 3, float32 = 4 };

// Fixed sizes of the header pieces, in bytes.
inline constexpr std::size_t kFixedHeaderBytes = 48;
inline constexpr std::size_t kFrameEntryBytes = 40;
// Largest width or height a header may declare; bounds every size computation.
inline constexpr std::uint32_t kMaxImageSide = 1u << 16;

// Encodes `set` as header part + one part per frame (camera 0 A, camera 0 B, camera 1 A, ...).
// Pixel parts reference the Images' buffers (no copy); a missing frame gets an empty part.
// Throws bad_input if the set cannot be expressed (too many cameras, an id over 65535 bytes).
std::vector<zmq::message_t> encode_frame_set(const FrameSet& set);

// Decodes a received message, taking ownership of its parts; the returned Images are views
// into them. Throws tomorig::Error (bad_input) naming the problem for anything malformed:
// wrong magic, other protocol version, truncated or inconsistent header, wrong part count,
// a pixel part whose size differs from its header entry. Never reads outside the parts.
FrameSet decode_frame_set(std::vector<zmq::message_t>&& parts);

// Session messages (docs/wire-protocol.md, "Session messages"), one part each. The encoders
// throw bad_input for what the layout cannot express (no camera, more
// than 32767 cameras, an id over 65535 bytes, a text over 16 MiB, session_id 0).
zmq::message_t encode_session_start(const SessionStart& start);
zmq::message_t encode_set_truth(const SetTruth& truth);
zmq::message_t encode_session_end(const SessionEnd& end);

// Decodes any stream message (frame set or session message), taking ownership of the parts.
// Throws tomorig::Error (bad_input) naming the problem for anything malformed: wrong magic or
// protocol version, unknown type, another session format version, truncated or trailing
// bytes, counts the message cannot hold, invalid values. Never reads outside the parts.
StreamMessage decode_stream_message(std::vector<zmq::message_t>&& parts);

// The pixel bytes one frame occupies on the wire: stride * (height - 1) + row bytes.
std::size_t wire_frame_bytes(const Image& image);

}  // namespace tomorig::stream
