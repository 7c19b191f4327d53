// Streaming minimum and mean images: one pass, one frame in memory at a time.
#include "tomorig/processing/preprocess/sequence_image.h"

#include <algorithm>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::preprocess {
namespace {

void check_size(const Image& frame, int width, int height, const char* what) {
  if (frame.empty()) throw bad_input(fmt::format("{}: the frame is empty (a missing frame cannot be added)", what));
  if (frame.width() != width || frame.height() != height)
    throw bad_input(fmt::format("{}: frame is {} x {} but the sequence is {} x {}; all frames must have one size", what,
                                frame.width(), frame.height(), width, height));
}

// Calls fn(x, y-row pointer as float) for each row, converting integer samples on the fly.
template <typename Fn>
void for_each_row(const Image& frame, Fn&& fn) {
  switch (frame.type()) {
    case SampleType::u8:
      for (int y = 0; y < frame.height(); ++y) fn(y, frame.row<std::uint8_t>(y));
      break;
    case SampleType::u16:
      for (int y = 0; y < frame.height(); ++y) fn(y, frame.row<std::uint16_t>(y));
      break;
    case SampleType::f32:
      for (int y = 0; y < frame.height(); ++y) fn(y, frame.row<float>(y));
      break;
  }
}

}  // namespace

void MinimumImage::add(const Image& frame) {
  if (count_ == 0) {
    if (frame.empty()) throw bad_input("minimum image: the frame is empty (a missing frame cannot be added)");
    minimum_ = Image::allocate(frame.width(), frame.height(), SampleType::f32);
    for_each_row(frame, [&](int y, const auto* in) {
      float* out = minimum_.row<float>(y);
      for (int x = 0; x < frame.width(); ++x) out[x] = static_cast<float>(in[x]);
    });
  } else {
    check_size(frame, minimum_.width(), minimum_.height(), "minimum image");
    for_each_row(frame, [&](int y, const auto* in) {
      float* out = minimum_.row<float>(y);
      for (int x = 0; x < frame.width(); ++x) out[x] = std::min(out[x], static_cast<float>(in[x]));
    });
  }
  ++count_;
}

const Image& MinimumImage::result() const {
  if (count_ == 0) throw bad_input("minimum image: no frame was added; the sequence is empty");
  return minimum_;
}

void MeanImage::add(const Image& frame) {
  if (count_ == 0) {
    if (frame.empty()) throw bad_input("average image: the frame is empty (a missing frame cannot be added)");
    width_ = frame.width();
    height_ = frame.height();
    sum_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_), 0.0);
  } else {
    check_size(frame, width_, height_, "average image");
  }
  for_each_row(frame, [&](int y, const auto* in) {
    double* out = sum_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width_);
    for (int x = 0; x < width_; ++x) out[x] += static_cast<double>(in[x]);
  });
  ++count_;
}

Image MeanImage::result() const {
  if (count_ == 0) throw bad_input("average image: no frame was added; the sequence is empty");
  Image mean = Image::allocate(width_, height_, SampleType::f32);
  const double scale = 1.0 / static_cast<double>(count_);
  for (int y = 0; y < height_; ++y) {
    float* out = mean.row<float>(y);
    const double* in = sum_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width_);
    for (int x = 0; x < width_; ++x) out[x] = static_cast<float>(in[x] * scale);
  }
  return mean;
}

}  // namespace tomorig::preprocess
