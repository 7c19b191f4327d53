#include "tomorig/acquisition/frame_set_assembler.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

using namespace std::chrono_literals;

// Pixels encode (camera, set, exposure), so a frame in the wrong slot shows up.
std::uint16_t tag(std::size_t camera, std::uint64_t index, Exposure e) {
  return static_cast<std::uint16_t>(1000 * camera + 10 * index + (e == Exposure::A ? 1 : 2));
}

CameraFrame make_frame(std::size_t camera, std::uint64_t index, Exposure e) {
  CameraFrame f;
  f.trigger_index = index;
  f.exposure = e;
  f.timestamp_ns = static_cast<std::int64_t>(index) * 100'000'000 + (e == Exposure::B ? 50'000 : 0);
  f.image = Image::allocate(4, 3, SampleType::u16);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) f.image.at<std::uint16_t>(x, y) = tag(camera, index, e);
  return f;
}

void add_pair(FrameSetAssembler& a, std::size_t camera, std::uint64_t index) {
  a.add_frame(camera, make_frame(camera, index, Exposure::A));
  a.add_frame(camera, make_frame(camera, index, Exposure::B));
}

void expect_tagged(const FrameSet& set, std::size_t camera, Exposure e) {
  const Frame& f = set.cameras[camera][e];
  ASSERT_TRUE(f.present()) << "camera " << camera << " set " << set.trigger_index;
  EXPECT_EQ(f.image.at<std::uint16_t>(3, 2), tag(camera, set.trigger_index, e));
}

struct ManualClock {
  std::int64_t now_ns = 0;
  AssemblyClock fn() {
    return [this] { return now_ns; };
  }
};

AssemblerOptions two_cameras() {
  AssemblerOptions o;
  o.camera_ids = {"cam0", "cam1"};
  o.timeout = 500ms;
  return o;
}

TEST(FrameSetAssembler, EmitsCompleteSetsAsSoonAsAllFramesArrived) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  for (std::uint64_t k = 0; k < 3; ++k) {
    add_pair(a, 0, k);
    EXPECT_FALSE(a.try_pop()) << "set " << k << " emitted with camera 1 missing";
    add_pair(a, 1, k);
    auto set = a.try_pop();
    ASSERT_TRUE(set);
    EXPECT_EQ(set->set_index, k);
    EXPECT_EQ(set->trigger_index, k);
    EXPECT_TRUE(set->complete());
    ASSERT_EQ(set->cameras.size(), 2u);
    EXPECT_EQ(set->cameras[1].camera_id, "cam1");
    for (std::size_t c = 0; c < 2; ++c)
      for (Exposure e : {Exposure::A, Exposure::B}) expect_tagged(*set, c, e);
    // No trigger was given: the trigger time stays unknown (0), never a camera's clock, which
    // would put one file's trigger_timestamp_ns on two clocks.
    EXPECT_EQ(set->trigger_timestamp_ns, 0);
    EXPECT_EQ(set->dt_ns, 0);
  }
  const auto s = a.statistics();
  EXPECT_EQ(s.sets_complete, 3u);
  EXPECT_EQ(s.sets_incomplete, 0u);
  EXPECT_EQ(s.cameras[0].frames_received, 6u);
  EXPECT_EQ(s.cameras[1].frames_missing, 0u);
}

TEST(FrameSetAssembler, MissingFrameGivesAnIncompleteFlaggedSetAfterTheTimeout) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  add_pair(a, 0, 0);
  a.add_frame(1, make_frame(1, 0, Exposure::A));  // camera 1 frame B is lost
  clock.now_ns = 499'000'000;
  a.expire();
  EXPECT_FALSE(a.try_pop()) << "emitted before the timeout";
  clock.now_ns = 500'000'000;
  auto set = a.try_pop();
  ASSERT_TRUE(set);
  EXPECT_FALSE(set->complete());
  EXPECT_EQ(set->missing_frames(), 1);
  EXPECT_FALSE(set->cameras[1].b.present());
  expect_tagged(*set, 1, Exposure::A);
  const auto s = a.statistics();
  EXPECT_EQ(s.sets_incomplete, 1u);
  EXPECT_EQ(s.cameras[1].frames_missing, 1u);
  EXPECT_EQ(s.cameras[0].frames_missing, 0u);
}

TEST(FrameSetAssembler, OutOfOrderArrivalStillBuildsEachSetFromItsOwnFrames) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  // Set 1 arrives first and complete, in reverse camera and exposure order; it must wait
  // behind set 0 (sets leave in trigger order).
  a.add_frame(1, make_frame(1, 1, Exposure::B));
  a.add_frame(0, make_frame(0, 1, Exposure::B));
  a.add_frame(1, make_frame(1, 1, Exposure::A));
  a.add_frame(0, make_frame(0, 1, Exposure::A));
  EXPECT_FALSE(a.try_pop());
  a.add_frame(1, make_frame(1, 0, Exposure::B));
  a.add_frame(0, make_frame(0, 0, Exposure::A));
  a.add_frame(1, make_frame(1, 0, Exposure::A));
  a.add_frame(0, make_frame(0, 0, Exposure::B));
  for (std::uint64_t k = 0; k < 2; ++k) {
    auto set = a.try_pop();
    ASSERT_TRUE(set);
    EXPECT_EQ(set->trigger_index, k);
    EXPECT_TRUE(set->complete());
    for (std::size_t c = 0; c < 2; ++c)
      for (Exposure e : {Exposure::A, Exposure::B}) expect_tagged(*set, c, e);
  }
  EXPECT_FALSE(a.try_pop());
}

TEST(FrameSetAssembler, LateFramesAreCountedAndDroppedNeverMergedIntoAnotherSet) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  add_pair(a, 0, 0);
  clock.now_ns = 600'000'000;
  auto first = a.try_pop();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->missing_frames(), 2);
  add_pair(a, 1, 0);  // camera 1's frames of set 0 arrive after set 0 left
  add_pair(a, 0, 1);
  add_pair(a, 1, 1);
  auto second = a.try_pop();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->trigger_index, 1u);
  EXPECT_TRUE(second->complete());
  expect_tagged(*second, 1, Exposure::A);
  EXPECT_FALSE(a.try_pop());
  const auto s = a.statistics();
  EXPECT_EQ(s.cameras[1].frames_late, 2u);
  EXPECT_EQ(s.cameras[1].frames_missing, 2u);
  EXPECT_EQ(s.cameras[0].frames_late, 0u);
  EXPECT_EQ(s.sets_emitted, 2u);
}

TEST(FrameSetAssembler, DuplicateFrameIsCountedAndTheFirstKept) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  a.add_frame(0, make_frame(0, 0, Exposure::A));
  CameraFrame dup = make_frame(0, 0, Exposure::A);
  dup.image.at<std::uint16_t>(3, 2) = 9;
  a.add_frame(0, std::move(dup));
  a.add_frame(0, make_frame(0, 0, Exposure::B));
  add_pair(a, 1, 0);
  auto set = a.try_pop();
  ASSERT_TRUE(set);
  expect_tagged(*set, 0, Exposure::A);
  EXPECT_EQ(a.statistics().cameras[0].frames_duplicate, 1u);
}

TEST(FrameSetAssembler, ASetWithNoFrameAtAllIsStillEmittedAndCounted) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  add_pair(a, 0, 0);
  add_pair(a, 1, 0);
  // Set 1 is lost on every camera; set 2 arrives complete.
  add_pair(a, 0, 2);
  add_pair(a, 1, 2);
  ASSERT_TRUE(a.try_pop());
  EXPECT_FALSE(a.try_pop()) << "set 2 overtook the missing set 1";
  clock.now_ns = 1'000'000'000;
  auto lost = a.try_pop();
  ASSERT_TRUE(lost);
  EXPECT_EQ(lost->trigger_index, 1u);
  EXPECT_EQ(lost->missing_frames(), 4);
  auto next = a.try_pop();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->trigger_index, 2u);
  EXPECT_EQ(next->set_index, 2u);
  EXPECT_EQ(a.statistics().sets_incomplete, 1u);
}

TEST(FrameSetAssembler, TriggerEventsGiveTimingAndExposeSetsNoCameraDelivered) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  a.add_trigger({0, 7'000, 123});
  a.add_trigger({1, 9'000, 456});
  add_pair(a, 0, 0);
  add_pair(a, 1, 0);
  auto set = a.try_pop();
  ASSERT_TRUE(set);
  EXPECT_EQ(set->trigger_timestamp_ns, 7'000);
  EXPECT_EQ(set->dt_ns, 123);
  EXPECT_FALSE(a.try_pop());
  clock.now_ns = 500'000'000;
  auto empty = a.try_pop();
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->trigger_index, 1u);
  EXPECT_EQ(empty->dt_ns, 456);
  EXPECT_EQ(empty->missing_frames(), 4);
}

TEST(FrameSetAssembler, FlushEmitsPendingSetsAtEndOfAcquisition) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  add_pair(a, 0, 0);
  a.flush();
  auto set = a.try_pop();
  ASSERT_TRUE(set);
  EXPECT_EQ(set->missing_frames(), 2);
}

TEST(FrameSetAssembler, RejectsBadCameraNumbersAndImplausibleIndices) {
  ManualClock clock;
  AssemblerOptions o = two_cameras();
  o.max_index_jump = 100;
  FrameSetAssembler a(o, clock.fn());
  a.add_frame(2, make_frame(0, 0, Exposure::A));
  a.add_frame(0, make_frame(0, 1'000'000, Exposure::A));
  EXPECT_EQ(a.statistics().frames_rejected, 2u);
  clock.now_ns = 10'000'000'000;
  EXPECT_FALSE(a.try_pop()) << "a bogus index created sets";
}

TEST(FrameSetAssembler, OptionsAreValidated) {
  AssemblerOptions o;
  EXPECT_THROW(FrameSetAssembler{o}, Error);
  o.camera_ids = {"a", "a"};
  try {
    FrameSetAssembler a(o);
    FAIL() << "duplicate ids accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("'a'"), std::string::npos) << e.what();
  }
  o.camera_ids = {"a"};
  o.timeout = 0ms;
  EXPECT_THROW(FrameSetAssembler{o}, Error);
}

TEST(FrameSetAssembler, ConcurrentCamerasAndAConsumerLoseNothing) {
  AssemblerOptions o;
  o.camera_ids = {"c0", "c1", "c2", "c3"};
  o.timeout = 60s;  // real clock: never expires during the test, so every set must be complete
  o.max_queued_sets = 4;  // small, so producers exercise the back-pressure wait
  FrameSetAssembler a(o);
  constexpr std::uint64_t kSets = 300;
  std::vector<std::thread> cameras;
  for (std::size_t c = 0; c < 4; ++c)
    cameras.emplace_back([&a, c] {
      for (std::uint64_t k = 0; k < kSets; ++k) add_pair(a, c, k);
    });
  std::uint64_t received = 0;
  while (received < kSets) {
    auto set = a.pop(30s);
    ASSERT_TRUE(set) << "timed out after " << received << " sets";
    EXPECT_EQ(set->trigger_index, received);
    EXPECT_TRUE(set->complete());
    expect_tagged(*set, 3, Exposure::B);
    ++received;
  }
  for (auto& t : cameras) t.join();
  const auto s = a.statistics();
  EXPECT_EQ(s.sets_complete, kSets);
  for (const auto& c : s.cameras) EXPECT_EQ(c.frames_missing + c.frames_late + c.frames_duplicate, 0u) << c.camera_id;
}

}  // namespace
}  // namespace tomorig::acquisition

// Pairing by time, the run's end, lost cameras and free-running cameras.
namespace tomorig::acquisition {
namespace {

CameraFrame frame_at(std::size_t camera, std::uint64_t index, Exposure e, std::int64_t timestamp_ns) {
  CameraFrame f = make_frame(camera, index, e);
  f.timestamp_ns = timestamp_ns;
  return f;
}

TEST(FrameSetAssemblerPairing, APairWhoseTimestampsDisagreeWithThePlanIsDroppedAndTheSetFlagged) {
  ManualClock clock;
  AssemblerOptions o = two_cameras();
  // The plan: B 60 ms after A, give or take 25 ms; camera 1 unchecked (tolerance 0).
  o.pairing = {{60'000'000, 25'000'000, false}, {}};
  FrameSetAssembler a(o, clock.fn());
  // Set 0: camera 0 pairs right (B - A = 80 ms, within 60 ± 25).
  a.add_frame(0, frame_at(0, 0, Exposure::A, 1'000'000'000));
  a.add_frame(0, frame_at(0, 0, Exposure::B, 1'080'000'000));
  add_pair(a, 1, 0);
  auto good = a.try_pop();
  ASSERT_TRUE(good);
  EXPECT_TRUE(good->complete());
  // Set 1: camera 0 missed a trigger, so its "B" is the next event's frame A, 140 ms later.
  a.add_frame(0, frame_at(0, 1, Exposure::A, 1'200'000'000));
  a.add_frame(0, frame_at(0, 1, Exposure::B, 1'340'000'000));
  add_pair(a, 1, 1);
  auto bad = a.try_pop();
  ASSERT_TRUE(bad);
  EXPECT_FALSE(bad->complete());
  EXPECT_FALSE(bad->cameras[0].a.present());  // neither frame of the mismatched pair is kept
  EXPECT_FALSE(bad->cameras[0].b.present());
  expect_tagged(*bad, 1, Exposure::A);
  const auto s = a.statistics();
  EXPECT_EQ(s.cameras[0].frames_mismatched, 2u);
  EXPECT_EQ(s.cameras[0].frames_missing, 2u);
  EXPECT_EQ(s.cameras[0].frames_received, 2u);  // set 0's pair
  EXPECT_EQ(s.sets_incomplete, 1u);
  EXPECT_NE(s.cameras[0].last_mismatch.find("140.000 ms apart"), std::string::npos) << s.cameras[0].last_mismatch;
  EXPECT_NE(s.cameras[0].last_mismatch.find("60.000 ms"), std::string::npos) << s.cameras[0].last_mismatch;
}

TEST(FrameSetAssemblerPairing, NeverMoreSetsThanTheRunAsked) {
  ManualClock clock;
  AssemblerOptions o = two_cameras();
  o.end_trigger_index = 2;
  FrameSetAssembler a(o, clock.fn());
  for (std::uint64_t k = 0; k < 4; ++k) {  // the cameras deliver two events too many
    add_pair(a, 0, k);
    add_pair(a, 1, k);
  }
  a.add_trigger({3, 300, 100});  // and the trigger announces one past the end
  a.flush();
  int sets = 0;
  while (auto set = a.try_pop()) {
    EXPECT_LT(set->trigger_index, 2u);
    ++sets;
  }
  EXPECT_EQ(sets, 2);
  EXPECT_EQ(a.statistics().cameras[0].frames_beyond_run, 4u);
}

TEST(FrameSetAssemblerPairing, SetsStopWaitingForALostCamera) {
  ManualClock clock;
  FrameSetAssembler a(two_cameras(), clock.fn());
  add_pair(a, 0, 0);
  EXPECT_FALSE(a.try_pop());
  a.mark_camera_lost(1);  // camera 1 is gone: no point waiting out the timeout
  auto set = a.try_pop();
  ASSERT_TRUE(set);
  EXPECT_EQ(set->missing_frames(), 2);
  EXPECT_TRUE(a.statistics().cameras[1].lost);
  add_pair(a, 0, 1);
  EXPECT_TRUE(a.try_pop()) << "a later set waited for the lost camera";
}

TEST(FrameSetAssemblerPairing, FreeRunningFramesFillAnnouncedSetsAndNeverMakeThemComplete) {
  ManualClock clock;
  AssemblerOptions o = two_cameras();
  o.pairing = {{}, {0, 0, true}};  // camera 1 runs free
  FrameSetAssembler a(o, clock.fn());
  a.add_frame(1, make_frame(1, 7, Exposure::A));  // before any event: no set waits for it
  clock.now_ns = 10;
  a.add_trigger({0, 1000, 100});
  add_pair(a, 0, 0);
  a.add_frame(1, make_frame(1, 99, Exposure::A));  // its own numbering means nothing
  a.add_frame(1, make_frame(1, 99, Exposure::B));
  auto set = a.try_pop();
  ASSERT_TRUE(set);
  EXPECT_EQ(set->missing_frames(), 0);
  EXPECT_TRUE(set->cameras[1].a.present() && set->cameras[1].b.present());
  EXPECT_FALSE(set->cameras[1].a.synchronised);
  EXPECT_TRUE(set->cameras[0].a.synchronised);
  EXPECT_EQ(set->unsynchronised_frames(), 2);
  EXPECT_FALSE(set->complete());
  const auto s = a.statistics();
  EXPECT_EQ(s.cameras[1].frames_surplus, 1u);
  EXPECT_EQ(s.sets_incomplete, 1u);
  EXPECT_EQ(s.sets_complete, 0u);
}

}  // namespace
}  // namespace tomorig::acquisition
