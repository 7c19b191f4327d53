#pragma once
// A 2-D image: either owning its pixels or a view over a foreign buffer (a camera buffer, a
// ZeroMQ message part). Copying an Image shares the buffer; clone() makes a deep copy. The
// buffer lives as long as the last Image that refers to it, so a view can hold a "lease"
// (a shared_ptr whose deleter returns the buffer to its camera stream or frees the message).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>

#include "tomorig/core/pixel_format.h"

namespace tomorig {

template <typename T>
constexpr SampleType sample_type_for() {
  if constexpr (std::is_same_v<T, std::uint8_t>) return SampleType::u8;
  else if constexpr (std::is_same_v<T, std::uint16_t>) return SampleType::u16;
  else {
    static_assert(std::is_same_v<T, float>, "Image samples are uint8, uint16 or float");
    return SampleType::f32;
  }
}

class Image {
 public:
  Image() = default;

  // A new zero-filled image with contiguous rows.
  static Image allocate(int width, int height, SampleType type);
  // A view over memory owned elsewhere. `lease` (may be empty) keeps that memory alive;
  // stride_bytes = 0 means rows are contiguous.
  static Image view(void* data, int width, int height, SampleType type, std::size_t stride_bytes = 0,
                    std::shared_ptr<void> lease = {});

  int width() const { return width_; }
  int height() const { return height_; }
  SampleType type() const { return type_; }
  std::size_t stride_bytes() const { return stride_; }
  std::size_t row_bytes() const { return static_cast<std::size_t>(width_) * bytes_per_sample(type_); }
  std::size_t size_bytes() const { return row_bytes() * static_cast<std::size_t>(height_); }
  bool empty() const { return data_ == nullptr; }
  bool contiguous() const { return stride_ == row_bytes(); }

  std::byte* data() { return data_; }
  const std::byte* data() const { return data_; }

  template <typename T>
  T* row(int y) {
    check_type(sample_type_for<T>());
    return reinterpret_cast<T*>(data_ + static_cast<std::size_t>(y) * stride_);
  }
  template <typename T>
  const T* row(int y) const {
    check_type(sample_type_for<T>());
    return reinterpret_cast<const T*>(data_ + static_cast<std::size_t>(y) * stride_);
  }
  template <typename T>
  T& at(int x, int y) { return row<T>(y)[x]; }
  template <typename T>
  const T& at(int x, int y) const { return row<T>(y)[x]; }

  // Pixel value converted to double, whatever the sample type; for tests and slow paths.
  double value(int x, int y) const;

  // A deep copy with contiguous rows.
  Image clone() const;
  // Copies the pixels row by row into `out`, which must hold size_bytes() bytes.
  void copy_to(std::span<std::byte> out) const;
  // True if sizes, types and every pixel are equal (strides may differ).
  bool same_pixels(const Image& other) const;

 private:
  void check_type(SampleType wanted) const;

  std::shared_ptr<void> lease_;
  std::byte* data_ = nullptr;
  int width_ = 0;
  int height_ = 0;
  std::size_t stride_ = 0;
  SampleType type_ = SampleType::u8;
};

}  // namespace tomorig
