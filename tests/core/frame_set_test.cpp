#include "tomorig/core/frame_set.h"

#include <gtest/gtest.h>

namespace tomorig {
namespace {

TEST(FrameSet, CountsMissingFrames) {
  FrameSet set;
  set.cameras.resize(3);
  for (auto& cam : set.cameras) {
    cam.a.image = Image::allocate(4, 4, SampleType::u16);
    cam.b.image = Image::allocate(4, 4, SampleType::u16);
  }
  EXPECT_TRUE(set.complete());
  set.cameras[1].b.image = Image{};
  EXPECT_EQ(set.missing_frames(), 1);
  EXPECT_FALSE(set.complete());
  EXPECT_FALSE(set.cameras[1][Exposure::B].present());
  EXPECT_TRUE(set.cameras[1][Exposure::A].present());
}

}  // namespace
}  // namespace tomorig
