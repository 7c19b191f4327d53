#pragma once
// Pixel formats as GenICam names them, and the in-memory sample type that holds each.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace tomorig {

// Sample type of an image buffer.
enum class SampleType : std::uint8_t { u8, u16, f32 };

std::size_t bytes_per_sample(SampleType type);
std::string_view to_string(SampleType type);
std::optional<SampleType> parse_sample_type(std::string_view name);

// Camera pixel formats (GenICam PFNC names). Mono12 is unpacked into 16-bit samples.
enum class PixelFormat : std::uint8_t { Mono8, Mono12, Mono16 };

std::string_view to_string(PixelFormat format);
std::optional<PixelFormat> parse_pixel_format(std::string_view name);
// "Mono8, Mono12, Mono16": for error messages that say what is allowed.
std::string supported_pixel_formats();
SampleType sample_type_of(PixelFormat format);
int bit_depth(PixelFormat format);

}  // namespace tomorig
