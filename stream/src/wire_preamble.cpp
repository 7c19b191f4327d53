#include "wire_preamble.h"

#include <cstring>

#include <fmt/format.h>

namespace tomorig::stream::detail {

void write_preamble(ByteWriter& w, MessageType type) {
  w.bytes(kWireMagic, 4);
  w.u16(kWireProtocolVersion);
  w.u16(static_cast<std::uint16_t>(type));
}

std::uint16_t read_preamble(ByteReader& r) {
  std::uint8_t magic[4];
  for (auto& m : magic) m = r.u8("magic");
  if (std::memcmp(magic, kWireMagic, 4) != 0)
    throw bad_input(fmt::format("wrong magic {:02x} {:02x} {:02x} {:02x}: not a tomorig stream message "
                                "(expected 'TMRG'); is the peer a tomorig stream?",
                                magic[0], magic[1], magic[2], magic[3]));
  const std::uint16_t version = r.u16("version");
  if (version != kWireProtocolVersion)
    throw bad_input(fmt::format("the peer speaks tomorig wire protocol version {} but this program speaks version "
                                "{}; run the same tomorig release on both ends",
                                version, kWireProtocolVersion));
  return r.u16("message_type");
}

const char* message_type_name(std::uint16_t type) {
  switch (static_cast<MessageType>(type)) {
    case MessageType::frame_set: return "frame set";
    case MessageType::session_start: return "session start";
    case MessageType::set_truth: return "set truth";
    case MessageType::session_end: return "session end";
  }
  return "unknown";
}

}  // namespace tomorig::stream::detail
