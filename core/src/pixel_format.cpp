#include "tomorig/core/pixel_format.h"

#include <array>
#include <utility>

namespace tomorig {
namespace {
constexpr std::array<std::pair<PixelFormat, std::string_view>, 3> kPixelFormatNames{{
    {PixelFormat::Mono8, "Mono8"}, {PixelFormat::Mono12, "Mono12"}, {PixelFormat::Mono16, "Mono16"}}};
constexpr std::array<std::pair<SampleType, std::string_view>, 3> kSampleTypeNames{{
    {SampleType::u8, "uint8"}, {SampleType::u16, "uint16"}, {SampleType::f32, "float32"}}};
}  // namespace

std::size_t bytes_per_sample(SampleType type) {
  switch (type) {
    case SampleType::u8: return 1;
    case SampleType::u16: return 2;
    case SampleType::f32: return 4;
  }
  return 0;
}

std::string_view to_string(SampleType type) {
  for (auto& [t, name] : kSampleTypeNames)
    if (t == type) return name;
  return "unknown";
}

std::optional<SampleType> parse_sample_type(std::string_view name) {
  for (auto& [t, n] : kSampleTypeNames)
    if (n == name) return t;
  return std::nullopt;
}

std::string_view to_string(PixelFormat format) {
  for (auto& [f, name] : kPixelFormatNames)
    if (f == format) return name;
  return "unknown";
}

std::optional<PixelFormat> parse_pixel_format(std::string_view name) {
  for (auto& [f, n] : kPixelFormatNames)
    if (n == name) return f;
  return std::nullopt;
}

std::string supported_pixel_formats() {
  std::string list;
  for (auto& [f, name] : kPixelFormatNames) {
    if (!list.empty()) list += ", ";
    list += name;
  }
  return list;
}

SampleType sample_type_of(PixelFormat format) {
  return format == PixelFormat::Mono8 ? SampleType::u8 : SampleType::u16;
}

int bit_depth(PixelFormat format) {
  switch (format) {
    case PixelFormat::Mono8: return 8;
    case PixelFormat::Mono12: return 12;
    case PixelFormat::Mono16: return 16;
  }
  return 0;
}

}  // namespace tomorig
