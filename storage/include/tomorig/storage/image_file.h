#pragma once
// Reading single-channel 8- and 16-bit images written by other tools (TIFF, including
// multi-page TIFF, PNG, and whatever else OpenCV reads), for imports and calibration
// targets, and writing PNG quick-looks. OpenCV stays inside storage/src.
#include <filesystem>
#include <string>
#include <string_view>

#include "tomorig/core/image.h"

namespace tomorig::storage {

// Number of pages (1 for single-page formats). Throws bad_input naming the file if it does
// not exist or is not an image OpenCV can read.
int image_page_count(const std::filesystem::path& file);

// One page as an owning Image of uint8 or uint16 samples, bit for bit as stored. Throws
// bad_input naming the file (and page) if it cannot be read or is not single-channel 8/16-bit.
Image read_image(const std::filesystem::path& file, int page = 0);

// Writes a u8 or u16 image as a lossless PNG (16-bit PNG for u16), through "<file>.partial"
// and a rename. Throws bad_input for a float image or an unwritable path.
void write_png(const std::filesystem::path& file, const Image& image);

// The same PNG as bytes in memory (for the preview stream). Throws bad_input for a float or
// empty image.
std::string encode_png(const Image& image);
// A single-channel 8- or 16-bit PNG from bytes. Throws bad_input naming `what` if the bytes
// are not such a PNG.
Image decode_png(std::string_view bytes, std::string_view what = "PNG data");

}  // namespace tomorig::storage
