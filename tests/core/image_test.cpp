#include "tomorig/core/image.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "tomorig/core/error.h"

namespace tomorig {
namespace {

TEST(Image, AllocateIsZeroedAndContiguous) {
  Image img = Image::allocate(7, 5, SampleType::u16);
  EXPECT_EQ(img.width(), 7);
  EXPECT_EQ(img.height(), 5);
  EXPECT_TRUE(img.contiguous());
  EXPECT_EQ(img.size_bytes(), 7u * 5u * 2u);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) EXPECT_EQ(img.at<std::uint16_t>(x, y), 0);
}

// The session writer hands frames this large to the disk with O_DIRECT without a copy only
// when they start on a memory page.
TEST(Image, MegapixelFramesStartOnAPageAndAreZeroed) {
  for (const int side : {512, 1000, 2048}) {
    Image img = Image::allocate(side, side, SampleType::u16);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(img.data()) % 4096, 0u) << side;
    EXPECT_EQ(img.at<std::uint16_t>(side - 1, side - 1), 0);
    EXPECT_EQ(img.at<std::uint16_t>(side / 2, side / 3), 0);
  }
}

TEST(Image, RejectsNonPositiveSizeWithBadInput) {
  try {
    Image::allocate(0, 5, SampleType::u8);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("0 x 5"), std::string::npos);
  }
}

TEST(Image, ViewWithStrideSharesForeignMemory) {
  // 3 x 2 float image inside rows of 5 floats: the view must honour the stride.
  std::vector<float> buffer(10);
  for (int i = 0; i < 10; ++i) buffer[i] = static_cast<float>(i);
  Image view = Image::view(buffer.data(), 3, 2, SampleType::f32, 5 * sizeof(float));
  EXPECT_FALSE(view.contiguous());
  EXPECT_EQ(view.at<float>(2, 1), 7.0f);
  buffer[6] = 42.0f;  // no copy was made
  EXPECT_EQ(view.at<float>(1, 1), 42.0f);
  EXPECT_DOUBLE_EQ(view.value(1, 1), 42.0);
}

TEST(Image, LeaseReleasedWhenLastCopyDies) {
  // The lease models a camera buffer returned to its stream when the last frame dies.
  int released = 0;
  auto storage = std::make_shared<std::vector<std::uint8_t>>(16, 3);
  {
    std::shared_ptr<void> lease(storage.get(), [&released, storage](void*) { ++released; });
    Image view = Image::view(storage->data(), 4, 4, SampleType::u8, 0, std::move(lease));
    Image copy = view;
    view = Image{};
    EXPECT_EQ(released, 0);
    EXPECT_EQ(copy.at<std::uint8_t>(3, 3), 3);
  }
  EXPECT_EQ(released, 1);
}

TEST(Image, CloneIsDeepAndCompactsStride) {
  std::vector<std::uint16_t> buffer(12);
  for (int i = 0; i < 12; ++i) buffer[i] = static_cast<std::uint16_t>(100 + i);
  Image view = Image::view(buffer.data(), 2, 3, SampleType::u16, 4 * sizeof(std::uint16_t));
  Image copy = view.clone();
  EXPECT_TRUE(copy.contiguous());
  EXPECT_TRUE(copy.same_pixels(view));
  buffer[0] = 0;
  EXPECT_FALSE(copy.same_pixels(view));
  EXPECT_EQ(copy.at<std::uint16_t>(0, 0), 100);
  EXPECT_EQ(copy.at<std::uint16_t>(1, 2), 109);
}

TEST(Image, WrongSampleTypeAccessThrows) {
  Image img = Image::allocate(2, 2, SampleType::u8);
  EXPECT_THROW((void)img.row<std::uint16_t>(0), Error);
}

TEST(Image, ViewRejectsStrideSmallerThanRow) {
  std::vector<std::uint8_t> buffer(16);
  EXPECT_THROW(Image::view(buffer.data(), 4, 4, SampleType::u8, 3), Error);
  EXPECT_THROW(Image::view(nullptr, 4, 4, SampleType::u8), Error);
}

TEST(PixelFormat, RoundTripsNamesAndListsSupported) {
  for (auto f : {PixelFormat::Mono8, PixelFormat::Mono12, PixelFormat::Mono16})
    EXPECT_EQ(parse_pixel_format(to_string(f)), f);
  EXPECT_FALSE(parse_pixel_format("Mono14").has_value());
  EXPECT_EQ(supported_pixel_formats(), "Mono8, Mono12, Mono16");
  EXPECT_EQ(sample_type_of(PixelFormat::Mono12), SampleType::u16);
  EXPECT_EQ(bit_depth(PixelFormat::Mono12), 12);
}

}  // namespace
}  // namespace tomorig
