#include "gentl_xml.h"

#include <arv.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <fstream>
#include <sstream>

#include "tomorig/core/error.h"

namespace tomorig::acquisition::gentl_detail {
namespace {

// Ports answer reads of any length in principle; some grabbers cap one transfer.
constexpr std::size_t kReadChunk = 64 * 1024;
// A GenICam description above this is a wrong length field, not a camera.
constexpr std::uint64_t kMaxXmlBytes = 64ull * 1024 * 1024;

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::uint64_t parse_hex(const std::string& text, const std::string& url) {
  std::string digits = text;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) digits = digits.substr(2);
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value, 16);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size())
    throw runtime_error(fmt::format("GenTL port URL '{}': '{}' is not a hexadecimal number", url, text));
  return value;
}

std::string percent_decoded(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    unsigned value = 0;
    if (text[i] == '%' && i + 2 < text.size() &&
        std::from_chars(text.data() + i + 1, text.data() + i + 3, value, 16).ec == std::errc()) {
      out.push_back(static_cast<char>(value));
      i += 2;
    } else {
      out.push_back(text[i]);
    }
  }
  return out;
}

std::string unzip(const std::string& zipped, const std::string& url) {
  ArvZip* zip = arv_zip_new(zipped.data(), zipped.size());
  if (zip == nullptr) throw runtime_error(fmt::format("GenTL port URL '{}': the zip archive cannot be read", url));
  std::string xml;
  std::string chosen;
  for (const GSList* item = arv_zip_get_file_list(zip); item != nullptr; item = item->next) {
    const char* name = arv_zip_file_get_name(static_cast<ArvZipFile*>(item->data));
    if (name == nullptr) continue;
    if (chosen.empty() || (ends_with(lower(name), ".xml") && !ends_with(lower(chosen), ".xml"))) chosen = name;
  }
  if (!chosen.empty()) {
    std::size_t size = 0;
    void* data = arv_zip_get_file(zip, chosen.c_str(), &size);
    if (data != nullptr) xml.assign(static_cast<const char*>(data), size);
    g_free(data);
  }
  arv_zip_free(zip);
  if (xml.empty())
    throw runtime_error(fmt::format("GenTL port URL '{}': the zip archive holds no readable GenICam file{}", url,
                                    chosen.empty() ? std::string() : fmt::format(" ('{}' did not inflate)", chosen)));
  return xml;
}

std::string port_url(Producer& producer, gentl::Handle port) {
  const auto& fn = producer.fn();
  std::uint32_t count = 0;
  if (fn.GCGetNumPortURLs(port, &count) == gentl::kSuccess && count > 0) {
    std::string url = info_string([&](gentl::InfoType* type, void* buffer, std::size_t* size) {
      return fn.GCGetPortURLInfo(port, 0, gentl::kUrlInfoUrl, type, buffer, size);
    });
    if (!url.empty()) return url;
  }
  // GenTL 1.0's call, deprecated since 1.1 but still offered by most producers.
  return info_string([&](gentl::InfoType*, void* buffer, std::size_t* size) {
    return fn.GCGetPortURL(port, static_cast<char*>(buffer), size);
  });
}

}  // namespace

PortUrl parse_port_url(const std::string& url) {
  PortUrl parsed;
  const auto colon = url.find(':');
  if (colon == std::string::npos) throw runtime_error(fmt::format("GenTL port URL '{}' has no scheme", url));
  const std::string scheme = lower(url.substr(0, colon));
  std::string rest = url.substr(colon + 1);
  rest = rest.substr(0, rest.find('?'));  // ?SchemaVersion=...: the description says it again
  if (scheme == "local") {
    while (!rest.empty() && rest.front() == '/') rest.erase(rest.begin());
    const auto first = rest.find(';');
    const auto second = first == std::string::npos ? std::string::npos : rest.find(';', first + 1);
    if (second == std::string::npos)
      throw runtime_error(fmt::format("GenTL port URL '{}': expected local:NAME;ADDRESS;LENGTH", url));
    parsed.scheme = PortUrl::Scheme::local;
    parsed.file_name = rest.substr(0, first);
    parsed.address = parse_hex(rest.substr(first + 1, second - first - 1), url);
    parsed.length = parse_hex(rest.substr(second + 1), url);
  } else if (scheme == "file") {
    // file:///abs/path, file:/abs/path or file://localhost/abs/path
    if (rest.rfind("//", 0) == 0) {
      rest = rest.substr(2);
      const auto slash = rest.find('/');
      rest = slash == std::string::npos ? rest : rest.substr(slash);
    }
    parsed.scheme = PortUrl::Scheme::file;
    parsed.file_name = percent_decoded(rest);
  } else {
    parsed.scheme = PortUrl::Scheme::other;
    parsed.file_name = rest;
  }
  parsed.zipped = ends_with(lower(parsed.file_name), ".zip");
  return parsed;
}

std::string fetch_port_xml(Producer& producer, gentl::Handle port, const std::string& what) {
  const std::string url = port_url(producer, port);
  if (url.empty())
    throw runtime_error(fmt::format("{}: the GenTL port gives no URL for its GenICam description", what));
  const PortUrl parsed = parse_port_url(url);
  std::string content;
  if (parsed.scheme == PortUrl::Scheme::local) {
    if (parsed.length == 0 || parsed.length > kMaxXmlBytes)
      throw runtime_error(fmt::format("{}: GenTL port URL '{}' gives a length of {} bytes", what, url, parsed.length));
    content.resize(parsed.length);
    for (std::uint64_t done = 0; done < parsed.length;) {
      std::size_t size = static_cast<std::size_t>(std::min<std::uint64_t>(kReadChunk, parsed.length - done));
      const gentl::Status status = producer.fn().GCReadPort(port, parsed.address + done, content.data() + done, &size);
      if (status != gentl::kSuccess || size == 0)
        throw runtime_error(fmt::format("{}: reading the GenICam description at {} ({}): {}", what, url,
                                        fmt::format("0x{:x}", parsed.address + done),
                                        producer.describe("GCReadPort", status)));
      done += size;
    }
  } else if (parsed.scheme == PortUrl::Scheme::file) {
    std::ifstream file(parsed.file_name, std::ios::binary);
    if (!file)
      throw runtime_error(fmt::format("{}: the GenICam description '{}' (port URL '{}') cannot be read", what,
                                      parsed.file_name, url));
    std::ostringstream text;
    text << file.rdbuf();
    content = text.str();
  } else {
    throw runtime_error(fmt::format("{}: GenTL port URL '{}' points to a web site; tomorig reads only local: and "
                                    "file: descriptions (download it and give it as file:)",
                                    what, url));
  }
  if (parsed.zipped) content = unzip(content, url);
  while (!content.empty() && content.back() == '\0') content.pop_back();
  if (content.empty())
    throw runtime_error(fmt::format("{}: the GenICam description at '{}' is empty", what, url));
  return content;
}

}  // namespace tomorig::acquisition::gentl_detail
