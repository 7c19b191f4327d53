#pragma once
// Key paths as messages print them: cameras[2].roi.width, cameras[0].features."Foo.Bar".
// Array indices are 0-based, the order of the entries in the file.
#include <cstddef>
#include <string>
#include <string_view>

namespace tomorig::config::detail {

inline bool is_bare_key(std::string_view key) {
  if (key.empty()) return false;
  for (char c : key) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

// Keys that TOML would need quoted are quoted, so the path can be pasted back into a file.
inline std::string child_path(std::string_view parent, std::string_view key) {
  std::string out(parent);
  if (!out.empty()) out += '.';
  if (is_bare_key(key)) {
    out += key;
  } else {
    out += '"';
    for (char c : key) {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
    out += '"';
  }
  return out;
}

inline std::string index_path(std::string_view array_path, std::size_t index) {
  return std::string(array_path) + "[" + std::to_string(index) + "]";
}

}  // namespace tomorig::config::detail
