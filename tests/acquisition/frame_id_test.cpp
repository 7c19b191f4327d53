#include "tomorig/acquisition/frame_id.h"

#include <gtest/gtest.h>

#include "tomorig/acquisition/frame_set_assembler.h"
#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

TEST(FrameIdUnwrapper, GigEVisionIdsSkipZeroAcrossTheWrap) {
  FrameIdUnwrapper u(16, /*zero_reserved=*/true);
  EXPECT_EQ(u.unwrap(65534), 0u);
  EXPECT_EQ(u.unwrap(65535), 1u);
  EXPECT_EQ(u.unwrap(1), 2u);  // 65535 -> 1 is the next frame, not a lost one
  EXPECT_EQ(u.unwrap(2), 3u);
  EXPECT_EQ(u.gaps(), 0u);
}

TEST(FrameIdUnwrapper, PlainSixteenBitCounterWrapsFrom65535ToZero) {
  FrameIdUnwrapper u(16, /*zero_reserved=*/false);
  EXPECT_EQ(u.unwrap(65535), 0u);
  EXPECT_EQ(u.unwrap(0), 1u);
  EXPECT_EQ(u.unwrap(1), 2u);
  EXPECT_EQ(u.gaps(), 0u);
}

TEST(FrameIdUnwrapper, CountsGapsAndRejectsStaleIds) {
  FrameIdUnwrapper u(16, true);
  EXPECT_EQ(u.unwrap(65530), 0u);
  EXPECT_EQ(u.unwrap(3), 8u);  // 65531..65535, 1, 2 never arrived: 7 frames
  EXPECT_EQ(u.gaps(), 7u);
  EXPECT_FALSE(u.unwrap(3));      // duplicate
  EXPECT_FALSE(u.unwrap(65531));  // from before the wrap
  EXPECT_EQ(u.unwrap(4), 9u);
}

TEST(FrameIdUnwrapper, KeepsCountingOverManyWraps) {
  FrameIdUnwrapper u(16, false);
  std::uint64_t last = 0;
  for (std::uint64_t i = 0; i < 3 * 65536 + 17; ++i) last = *u.unwrap(i & 0xFFFF);
  EXPECT_EQ(last, 3u * 65536 + 16);
}

TEST(FrameIdUnwrapper, AKnownFirstIdKeepsRolesWhenTheFirstFrameIsLost) {
  FrameIdUnwrapper u(16, true);
  u.expect_first(1);           // the camera restarts at 1 on AcquisitionStart
  EXPECT_EQ(u.unwrap(2), 1u);  // frame 1 (id 1, frame A of set 0) never arrived
  EXPECT_EQ(u.gaps(), 1u);
  EXPECT_EQ(u.unwrap(3), 2u);  // frame A of set 1

  FrameIdUnwrapper at_wrap(16, true);
  at_wrap.expect_first(65535);
  EXPECT_EQ(at_wrap.unwrap(65535), 0u);
  EXPECT_EQ(at_wrap.unwrap(1), 1u);
  EXPECT_EQ(at_wrap.gaps(), 0u);
}

TEST(FrameIdUnwrapper, RejectsImpossibleWidths) {
  EXPECT_THROW(FrameIdUnwrapper(1, false), Error);
  EXPECT_THROW(FrameIdUnwrapper(64, false), Error);
}

// A double-frame camera whose 16-bit frame id wraps from 65535 to 0 mid-run: the frames on
// either side of the wrap still land in consecutive sets with the right A/B role.
TEST(FrameIdUnwrapper, AssemblyAcrossTheWrapKeepsSetsAndRoles) {
  std::int64_t now = 0;
  AssemblerOptions o;
  o.camera_ids = {"cam0"};
  FrameSetAssembler assembler(o, [&] { return now; });
  FrameIdUnwrapper u(16, false);
  std::uint64_t raw = 65532;  // frames 65532, 65533 | 65534, 65535 | 0, 1 | 2, 3
  for (int i = 0; i < 8; ++i, raw = (raw + 1) & 0xFFFF) {
    const auto seq = u.unwrap(raw);
    ASSERT_TRUE(seq);
    CameraFrame f;
    f.frame_id = *seq;
    f.trigger_index = *seq / 2;
    f.exposure = *seq % 2 == 0 ? Exposure::A : Exposure::B;
    f.image = Image::allocate(2, 2, SampleType::u16);
    f.image.at<std::uint16_t>(0, 0) = static_cast<std::uint16_t>(raw);
    assembler.add_frame(0, std::move(f));
  }
  const std::uint16_t expected[4][2] = {{65532, 65533}, {65534, 65535}, {0, 1}, {2, 3}};
  for (std::uint64_t k = 0; k < 4; ++k) {
    auto set = assembler.try_pop();
    ASSERT_TRUE(set) << "set " << k;
    EXPECT_EQ(set->trigger_index, k);
    ASSERT_TRUE(set->complete());
    EXPECT_EQ(set->cameras[0].a.image.at<std::uint16_t>(0, 0), expected[k][0]);
    EXPECT_EQ(set->cameras[0].b.image.at<std::uint16_t>(0, 0), expected[k][1]);
  }
  EXPECT_EQ(assembler.statistics().sets_incomplete, 0u);
}

}  // namespace
}  // namespace tomorig::acquisition
