#include "tomorig/core/image.h"

#include <cstdlib>
#include <cstring>
#include <new>
#include <string>

#include "tomorig/core/error.h"

namespace tomorig {
namespace {

// Frames of a megapixel camera start on a memory page: the session writer then hands them to the
// disk with O_DIRECT as they are (storage/src/direct_write_driver.h), without a copy.
constexpr std::size_t kPage = 4096;
constexpr std::size_t kPageAlignFrom = 256 * 1024;

std::shared_ptr<std::byte[]> zeroed_buffer(std::size_t bytes) {
  if (bytes < kPageAlignFrom) return std::make_shared<std::byte[]>(bytes);  // value-initialised: zeros
  void* memory = std::aligned_alloc(kPage, (bytes + kPage - 1) / kPage * kPage);
  if (memory == nullptr) throw std::bad_alloc();
  std::memset(memory, 0, bytes);
  return std::shared_ptr<std::byte[]>(static_cast<std::byte*>(memory), [](std::byte* p) { std::free(p); });
}

}  // namespace

Image Image::allocate(int width, int height, SampleType type) {
  if (width <= 0 || height <= 0)
    throw bad_input("image size " + std::to_string(width) + " x " + std::to_string(height) +
                    " is invalid: width and height must be > 0");
  Image image;
  image.width_ = width;
  image.height_ = height;
  image.type_ = type;
  image.stride_ = image.row_bytes();
  auto buffer = zeroed_buffer(image.size_bytes());
  image.data_ = buffer.get();
  image.lease_ = std::move(buffer);
  return image;
}

Image Image::view(void* data, int width, int height, SampleType type, std::size_t stride_bytes,
                  std::shared_ptr<void> lease) {
  if (data == nullptr) throw bad_input("image view over a null buffer");
  if (width <= 0 || height <= 0)
    throw bad_input("image size " + std::to_string(width) + " x " + std::to_string(height) +
                    " is invalid: width and height must be > 0");
  Image image;
  image.width_ = width;
  image.height_ = height;
  image.type_ = type;
  image.stride_ = stride_bytes == 0 ? image.row_bytes() : stride_bytes;
  if (image.stride_ < image.row_bytes())
    throw bad_input("image stride " + std::to_string(stride_bytes) + " bytes is smaller than a row (" +
                    std::to_string(image.row_bytes()) + " bytes)");
  image.data_ = static_cast<std::byte*>(data);
  image.lease_ = std::move(lease);
  return image;
}

void Image::check_type(SampleType wanted) const {
  if (wanted != type_)
    throw runtime_error(std::string("image holds ") + std::string(to_string(type_)) +
                        " samples but was accessed as " + std::string(to_string(wanted)));
}

double Image::value(int x, int y) const {
  const std::byte* p = data_ + static_cast<std::size_t>(y) * stride_;
  switch (type_) {
    case SampleType::u8: return reinterpret_cast<const std::uint8_t*>(p)[x];
    case SampleType::u16: return reinterpret_cast<const std::uint16_t*>(p)[x];
    case SampleType::f32: return reinterpret_cast<const float*>(p)[x];
  }
  return 0;
}

Image Image::clone() const {
  if (empty()) return {};
  Image copy = allocate(width_, height_, type_);
  copy_to(std::span<std::byte>(copy.data_, copy.size_bytes()));
  return copy;
}

void Image::copy_to(std::span<std::byte> out) const {
  if (out.size() < size_bytes())
    throw runtime_error("image copy target holds " + std::to_string(out.size()) + " bytes, needs " +
                        std::to_string(size_bytes()));
  const std::size_t rb = row_bytes();
  if (contiguous()) {
    std::memcpy(out.data(), data_, size_bytes());
    return;
  }
  for (int y = 0; y < height_; ++y)
    std::memcpy(out.data() + static_cast<std::size_t>(y) * rb, data_ + static_cast<std::size_t>(y) * stride_, rb);
}

bool Image::same_pixels(const Image& other) const {
  if (width_ != other.width_ || height_ != other.height_ || type_ != other.type_) return false;
  const std::size_t rb = row_bytes();
  for (int y = 0; y < height_; ++y)
    if (std::memcmp(data_ + static_cast<std::size_t>(y) * stride_,
                    other.data_ + static_cast<std::size_t>(y) * other.stride_, rb) != 0)
      return false;
  return true;
}

}  // namespace tomorig
