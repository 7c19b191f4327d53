#include "tomorig/core/camera_id.h"

#include <cstdint>

#include "tomorig/core/error.h"

namespace tomorig {
namespace {

std::string hex_byte(unsigned char byte) {
  constexpr char kDigits[] = "0123456789abcdef";
  return std::string("\\x") + kDigits[byte >> 4] + kDigits[byte & 0xf];
}

std::string code_point_name(std::uint32_t cp) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  std::string hex;
  for (int shift = 12; shift >= 0; shift -= 4) hex += kDigits[(cp >> shift) & 0xf];
  return "U+" + hex;
}

// Decodes the UTF-8 sequence at text[i]: its code point and length, or nothing if the bytes
// are not well-formed UTF-8 (overlong forms, surrogates and values past U+10FFFF included).
struct Decoded {
  std::uint32_t code_point;
  std::size_t length;
};
std::optional<Decoded> decode_utf8(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  if (lead < 0x80) return Decoded{lead, 1};
  std::size_t length = 0;
  std::uint32_t cp = 0, min = 0;
  if ((lead & 0xe0) == 0xc0) length = 2, cp = lead & 0x1f, min = 0x80;
  else if ((lead & 0xf0) == 0xe0) length = 3, cp = lead & 0x0f, min = 0x800;
  else if ((lead & 0xf8) == 0xf0) length = 4, cp = lead & 0x07, min = 0x10000;
  else return std::nullopt;
  if (i + length > text.size()) return std::nullopt;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xc0) != 0x80) return std::nullopt;
    cp = (cp << 6) | (byte(i + k) & 0x3f);
  }
  if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return std::nullopt;
  return Decoded{cp, length};
}

}  // namespace

std::optional<std::string> camera_id_problem(std::string_view id) {
  if (id.empty()) return "is empty";
  if (id.size() > kMaxCameraIdBytes)
    return "is " + std::to_string(id.size()) + " bytes long; at most " + std::to_string(kMaxCameraIdBytes) +
           " are allowed";
  if (id == "." || id == "..") return "is '.' or '..', which name folders";
  for (std::size_t i = 0; i < id.size();) {
    const auto decoded = decode_utf8(id, i);
    if (!decoded)
      return "is not valid UTF-8 (byte " + hex_byte(static_cast<unsigned char>(id[i])) + " at offset " +
             std::to_string(i) + ")";
    const std::uint32_t cp = decoded->code_point;
    if (cp == 0) return "contains a NUL byte";
    if (cp < 0x20 || (cp >= 0x7f && cp <= 0x9f)) return "contains the control character " + code_point_name(cp);
    if (cp == '/') return "contains '/', which separates folders";
    i += decoded->length;
  }
  return std::nullopt;
}

std::string printable(std::string_view text) {
  constexpr std::size_t kShown = 64;
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < kShown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') out += static_cast<char>(c);
    else out += c == '\\' ? std::string("\\\\") : hex_byte(c);
  }
  if (text.size() > kShown) out += "...";
  return out;
}

void require_valid_camera_id(std::string_view id, std::string_view context) {
  if (const auto problem = camera_id_problem(id))
    throw bad_input(std::string(context) + ": camera id \"" + printable(id) + "\" is not allowed: it " + *problem +
                    " (ids are 1 to " + std::to_string(kMaxCameraIdBytes) +
                    " bytes of UTF-8 without '/', control characters, '.' or '..')");
}

}  // namespace tomorig
