#pragma once
// The first 8 bytes every tomorig stream message starts with: magic "TMRG", protocol version,
// message type (docs/wire-protocol.md). Frame sets and session messages share them, so a
// receiver can tell the kinds apart and refuse a foreign or newer peer before reading further.
#include "byte_io.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream::detail {

void write_preamble(ByteWriter& w, MessageType type);

// Checks magic and protocol version (bad_input naming both versions on a mismatch, read from
// bytes 4-5 before anything else) and returns the raw message type, unchecked.
std::uint16_t read_preamble(ByteReader& r);

// "frame set", "session start", ...; "unknown" for other codes.
const char* message_type_name(std::uint16_t type);

}  // namespace tomorig::stream::detail
