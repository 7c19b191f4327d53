// Writing a session and reading it back gives exactly what was written.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include "storage_test_support.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/session_summary.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;
using testing::test_camera;
using testing::test_image;
using testing::test_set;

SessionTruth test_truth() {
  SessionTruth truth;
  truth.case_name = "tpiv-thesis";
  truth.flow_name = "taylor-green";
  truth.flow_parameters = R"({"A_voxel":5,"p_voxel":256})";
  truth.seed = 0xFEEDFACECAFEBEEFull;  // above 2^63: must survive as uint64
  truth.ppp = 0.05;
  for (int c = 0; c < 2; ++c) {
    TruthCamera cam;
    cam.id = "cam" + std::to_string(c);
    cam.K = {5000, 0, 31.5, 0, 5000, 23.5, 0, 0, 1};
    cam.R = {0.9, 0.1, 0.2, -0.1, 0.95, 0.3, 0.25, -0.3, 0.92 + c};
    cam.t = {1.5, -2.25, 263.16 + c};
    cam.width = 64;
    cam.height = 48;
    truth.cameras.push_back(cam);
  }
  return truth;
}

TruthSet test_truth_set(int n, double offset) {
  TruthSet t;
  for (int i = 0; i < n; ++i) {
    t.particles_a.push_back({i * 0.1 + offset, -i * 0.2, 1.0 / (i + 1)});
    t.particles_b.push_back({i * 0.1 + offset + 1e-7, -i * 0.2 + 3e-9, 1.0 / (i + 1) - 1e-12});
  }
  return t;
}

void expect_vec_eq(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].y, b[i].y);
    EXPECT_EQ(a[i].z, b[i].z);
  }
}

void expect_same_frame(const Frame& got, const Frame& want, const std::string& what) {
  EXPECT_EQ(got.timestamp_ns, want.timestamp_ns) << what;
  ASSERT_EQ(got.present(), want.present()) << what;
  if (want.present()) {
    EXPECT_TRUE(got.image.same_pixels(want.image)) << what;
  }
}

class RoundTrip : public ::testing::TestWithParam<std::tuple<PixelFormat, Compression>> {};

TEST_P(RoundTrip, EverythingReadsBackBitIdentical) {
  const auto [format, compression] = GetParam();
  TempDir dir;
  const fs::path path = dir / "session.h5";
  // Two cameras of different sizes: sizes are per camera, and an index mix-up would show.
  const std::vector<SessionCamera> cameras{test_camera("cam0", 64, 48, format), test_camera("cam1", 40, 30, format)};
  SessionInfo info;
  info.cameras = cameras;
  info.rig_config_toml = "name = \"rig with ünïcödé\"\n[trigger]\ndt_us = 100.0\n";

  std::vector<FrameSet> written;
  for (std::uint64_t s = 0; s < 4; ++s) written.push_back(test_set(cameras, s));
  written[1].cameras[1].b.image = Image();  // lost frame
  written[2].cameras[0].a.image = Image();
  written[2].cameras[0].b.image = Image();
  const SessionTruth truth = test_truth();
  {
    SessionWriter writer(path, info, testing::writer_options(compression));
    for (const auto& set : written) writer.append(set);
    writer.write_truth_set(1, test_truth_set(50, 1.0));
    writer.write_truth(truth);
    writer.write_truth_set(0, test_truth_set(100, 0.0));
    writer.write_truth_set(3, TruthSet{});  // no particles: still a valid entry
    EXPECT_EQ(writer.sets_written(), 4u);
    EXPECT_TRUE(fs::exists(writer.partial_path()));
    EXPECT_FALSE(fs::exists(path));
    writer.finish();
    EXPECT_FALSE(fs::exists(writer.partial_path()));
  }
  ASSERT_TRUE(fs::exists(path));

  SessionReader reader(path);
  EXPECT_EQ(reader.format_version(), 2);
  EXPECT_EQ(reader.info().rig_config_toml, info.rig_config_toml);
  EXPECT_EQ(reader.info().compression, compression);
  EXPECT_FALSE(reader.info().software_version.empty());
  EXPECT_EQ(reader.info().created_utc.size(), 20u) << reader.info().created_utc;  // 2024-05-01T12:34:56Z
  ASSERT_EQ(reader.info().cameras.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    const SessionCamera& got = reader.info().cameras[c];
    EXPECT_EQ(got.id, cameras[c].id);
    EXPECT_EQ(got.width, cameras[c].width);
    EXPECT_EQ(got.height, cameras[c].height);
    EXPECT_EQ(got.pixel_format, cameras[c].pixel_format);
    EXPECT_EQ(got.pixel_pitch_um, cameras[c].pixel_pitch_um);
  }
  ASSERT_EQ(reader.set_count(), 4u);
  EXPECT_EQ(reader.missing_frames(), 3);
  EXPECT_EQ(reader.incomplete_sets(), 2);
  for (std::uint64_t s = 0; s < 4; ++s) {
    const FrameSet got = reader.read_set(s);
    const FrameSet& want = written[s];
    EXPECT_EQ(got.set_index, s);
    EXPECT_EQ(got.trigger_index, want.trigger_index);
    EXPECT_EQ(got.trigger_timestamp_ns, want.trigger_timestamp_ns);
    EXPECT_EQ(got.dt_ns, want.dt_ns);
    ASSERT_EQ(got.cameras.size(), 2u);
    for (std::size_t c = 0; c < 2; ++c) {
      EXPECT_EQ(got.cameras[c].camera_id, cameras[c].id);
      const std::string what = "set " + std::to_string(s) + " camera " + cameras[c].id;
      expect_same_frame(got.cameras[c].a, want.cameras[c].a, what + " A");
      expect_same_frame(got.cameras[c].b, want.cameras[c].b, what + " B");
    }
    EXPECT_EQ(got.missing_frames(), want.missing_frames());
  }

  ASSERT_TRUE(reader.has_truth());
  const SessionTruth t = reader.truth();
  EXPECT_EQ(t.case_name, truth.case_name);
  EXPECT_EQ(t.flow_name, truth.flow_name);
  EXPECT_EQ(t.flow_parameters, truth.flow_parameters);
  EXPECT_EQ(t.seed, truth.seed);
  EXPECT_EQ(t.ppp, truth.ppp);
  ASSERT_EQ(t.cameras.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(t.cameras[c].id, truth.cameras[c].id);
    EXPECT_EQ(t.cameras[c].model, "pinhole");
    EXPECT_EQ(t.cameras[c].K, truth.cameras[c].K);
    EXPECT_EQ(t.cameras[c].R, truth.cameras[c].R);
    EXPECT_EQ(t.cameras[c].t.z, truth.cameras[c].t.z);
    EXPECT_EQ(t.cameras[c].width, 64);
    EXPECT_EQ(t.cameras[c].height, 48);
  }
  EXPECT_EQ(reader.truth_set_count(), 3u);
  EXPECT_TRUE(reader.has_truth_set(0));
  EXPECT_FALSE(reader.has_truth_set(2));
  const TruthSet ts0 = reader.truth_set(0);
  const TruthSet want0 = test_truth_set(100, 0.0);
  expect_vec_eq(ts0.particles_a, want0.particles_a);
  expect_vec_eq(ts0.particles_b, want0.particles_b);
  expect_vec_eq(reader.truth_set(1).particles_b, test_truth_set(50, 1.0).particles_b);
  EXPECT_TRUE(reader.truth_set(3).particles_a.empty());
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip,
                         ::testing::Combine(::testing::Values(PixelFormat::Mono8, PixelFormat::Mono12,
                                                              PixelFormat::Mono16),
                                            ::testing::Values(Compression::none, Compression::bitshuffle_lz4)),
                         [](const auto& info) {
                           return std::string(to_string(std::get<0>(info.param))) + "_" +
                                  (std::get<1>(info.param) == Compression::none ? "raw" : "bitshuffle_lz4");
                         });

TEST(SessionWriter, BitshuffleFilterIsOnTheFramesAndShrinksSmoothImages) {
  TempDir dir;
  const std::vector<SessionCamera> cameras{test_camera("cam0", 256, 256, PixelFormat::Mono16)};
  auto smooth_set = [&](std::uint64_t s) {
    FrameSet set;
    set.cameras.push_back({"cam0", {}, {}});
    for (Frame* f : {&set.cameras[0].a, &set.cameras[0].b}) {
      f->image = Image::allocate(256, 256, SampleType::u16);
      for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 256; ++x) f->image.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>((x + y + s) % 64);
    }
    return set;
  };
  for (Compression c : {Compression::none, Compression::bitshuffle_lz4}) {
    const fs::path path = dir / (std::string(to_string(c)) + ".h5");
    SessionInfo info;
    info.cameras = cameras;
    SessionWriter writer(path, info, testing::writer_options(c));
    for (std::uint64_t s = 0; s < 8; ++s) writer.append(smooth_set(s));
    writer.finish();
  }
  EXPECT_LT(fs::file_size(dir / "bitshuffle-lz4.h5") * 4, fs::file_size(dir / "none.h5"));

  // The filter recorded on the dataset is what h5py or MATLAB will need: 32008.
  const hid_t file = H5Fopen((dir / "bitshuffle-lz4.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t ds = H5Dopen2(file, "/cameras/cam0/frames", H5P_DEFAULT);
  const hid_t dcpl = H5Dget_create_plist(ds);
  ASSERT_EQ(H5Pget_nfilters(dcpl), 1);
  unsigned flags = 0, values[8] = {};
  std::size_t n_values = 8;
  EXPECT_EQ(H5Pget_filter2(dcpl, 0, &flags, &n_values, values, 0, nullptr, nullptr), 32008);
  ASSERT_EQ(n_values, 5u);  // plugin version (2), element size, block size, compression
  EXPECT_EQ(values[2], 2u);  // uint16
  EXPECT_EQ(values[4], 2u);  // LZ4
  H5Pclose(dcpl);
  H5Dclose(ds);
  H5Fclose(file);

  SessionReader reader(dir / "bitshuffle-lz4.h5");
  EXPECT_TRUE(reader.read_set(5).cameras[0].b.image.same_pixels(smooth_set(5).cameras[0].b.image));
}

TEST(SessionWriter, WritesImagesWithPaddedRows) {
  TempDir dir;
  const std::vector<SessionCamera> cameras{test_camera("cam0", 30, 20, PixelFormat::Mono16)};
  // A view into a wider buffer, as a camera driver with row padding would hand over.
  Image wide = test_image(37, 20, SampleType::u16, 7);
  Image view = Image::view(wide.data(), 30, 20, SampleType::u16, wide.stride_bytes());
  FrameSet set;
  set.cameras.push_back({"cam0", {view, 5}, {view, 6}});
  SessionInfo info;
  info.cameras = cameras;
  {
    SessionWriter writer(dir / "s.h5", info);
    writer.append(set);
    writer.finish();
  }
  SessionReader reader(dir / "s.h5");
  EXPECT_TRUE(reader.read_set(0).cameras[0].a.image.same_pixels(view));
}

TEST(SessionWriter, MatchesCamerasByIdAndCountsAbsentCamerasAsMissing) {
  TempDir dir;
  const std::vector<SessionCamera> cameras{test_camera("left", 16, 8, PixelFormat::Mono8),
                                           test_camera("right", 16, 8, PixelFormat::Mono8),
                                           test_camera("top", 16, 8, PixelFormat::Mono8)};
  FrameSet full = test_set(cameras, 0);
  FrameSet shuffled;
  shuffled.cameras = {full.cameras[2], full.cameras[0]};  // "right" absent, order differs
  SessionInfo info;
  info.cameras = cameras;
  {
    SessionWriter writer(dir / "s.h5", info);
    writer.append(shuffled);
    writer.finish();
  }
  SessionReader reader(dir / "s.h5");
  const FrameSet got = reader.read_set(0);
  ASSERT_EQ(got.cameras.size(), 3u);
  EXPECT_EQ(got.cameras[0].camera_id, "left");
  EXPECT_TRUE(got.cameras[0].a.image.same_pixels(full.cameras[0].a.image));
  EXPECT_TRUE(got.cameras[2].b.image.same_pixels(full.cameras[2].b.image));
  EXPECT_FALSE(got.cameras[1].a.present());
  EXPECT_FALSE(got.cameras[1].b.present());
  EXPECT_EQ(reader.missing_frames(), 2);
  const SetRecord record = reader.set_record(0);
  EXPECT_EQ(record.frame_present[1][0], false);
  EXPECT_EQ(record.frame_present[2][1], true);
}

TEST(SessionWriter, MissingFramesTakeNoSpace) {
  TempDir dir;
  const std::vector<SessionCamera> cameras{test_camera("cam0", 512, 512, PixelFormat::Mono16)};
  SessionInfo info;
  info.cameras = cameras;
  {
    SessionWriter writer(dir / "s.h5", info);
    for (int s = 0; s < 10; ++s) {
      FrameSet set;
      set.cameras.push_back({"cam0", {}, {}});  // every frame lost
      writer.append(set);
    }
    writer.finish();
  }
  EXPECT_LT(fs::file_size(dir / "s.h5"), 512u * 512u * 2u);  // less than one frame
  SessionReader reader(dir / "s.h5");
  EXPECT_EQ(reader.missing_frames(), 20);
  EXPECT_EQ(reader.incomplete_sets(), 10);
  EXPECT_FALSE(reader.read_set(9).cameras[0].a.present());
}

TEST(SessionWriter, EmptySessionReadsBack) {
  TempDir dir;
  testing::write_test_session(dir / "empty.h5", {test_camera("cam0", 8, 8, PixelFormat::Mono8)}, 0);
  SessionReader reader(dir / "empty.h5");
  EXPECT_EQ(reader.set_count(), 0u);
  EXPECT_EQ(reader.missing_frames(), 0);
  EXPECT_FALSE(reader.has_truth());
  const SessionSummary summary = summarize(reader);
  EXPECT_EQ(summary.sets, 0u);
  EXPECT_EQ(summary.time_span_s, 0.0);
}

TEST(SessionWriter, AbandonedWriterLeavesNothing) {
  TempDir dir;
  const fs::path path = dir / "s.h5";
  {
    SessionInfo info;
    info.cameras = {test_camera("cam0", 8, 8, PixelFormat::Mono8)};
    SessionWriter writer(path, info);
    writer.append(test_set(info.cameras, 0));
    EXPECT_TRUE(fs::exists(writer.partial_path()));
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(SessionWriter, OverwriteReplacesAnExistingSession) {
  TempDir dir;
  const fs::path path = dir / "s.h5";
  const std::vector<SessionCamera> cameras{test_camera("cam0", 8, 8, PixelFormat::Mono8)};
  testing::write_test_session(path, cameras, 1);
  testing::write_test_session(path, cameras, 3, testing::writer_options(Compression::none, true));
  EXPECT_EQ(SessionReader(path).set_count(), 3u);
}

TEST(SessionSummary, ReportsTimingAndTruth) {
  TempDir dir;
  const std::vector<SessionCamera> cameras{test_camera("cam0", 8, 8, PixelFormat::Mono8)};
  SessionInfo info;
  info.cameras = cameras;
  {
    SessionWriter writer(dir / "s.h5", info, testing::writer_options(Compression::bitshuffle_lz4));
    for (std::uint64_t s = 0; s < 5; ++s) writer.append(test_set(cameras, s));
    writer.write_truth(test_truth());
    writer.write_truth_set(0, test_truth_set(3, 0));
    writer.finish();
  }
  SessionReader reader(dir / "s.h5");
  const SessionSummary s = summarize(reader);
  EXPECT_EQ(s.sets, 5u);
  EXPECT_EQ(s.dt_ns_min, 100'000);
  EXPECT_EQ(s.dt_ns_max, 100'004);
  EXPECT_DOUBLE_EQ(s.time_span_s, 0.4);
  EXPECT_EQ(s.first_trigger_index, 1000u);
  EXPECT_EQ(s.last_trigger_index, 1004u);
  EXPECT_TRUE(s.truth);
  EXPECT_EQ(s.truth_case, "tpiv-thesis");
  EXPECT_EQ(s.truth_sets, 1u);
  EXPECT_EQ(s.compression, Compression::bitshuffle_lz4);
  EXPECT_GT(s.file_size_bytes, 0u);
}

TEST(Compression, NamesRoundTrip) {
  for (Compression c : {Compression::none, Compression::bitshuffle_lz4})
    EXPECT_EQ(parse_compression(to_string(c)), c);
  EXPECT_FALSE(parse_compression("gzip").has_value());
}

}  // namespace
}  // namespace tomorig::storage

namespace tomorig::storage {
namespace {

// frame_present = 2: a free-running camera's frame is kept, and its set is not complete.
TEST(SessionRoundTrip, AnUnsynchronisedFrameIsKeptAndItsSetIsIncomplete) {
  tomorig::testing::TempDir dir;
  const auto path = dir / "free.h5";
  const std::vector<SessionCamera> cameras = {test_camera("cam0", 8, 6, PixelFormat::Mono16),
                                              test_camera("cam1", 8, 6, PixelFormat::Mono16)};
  SessionInfo info;
  info.cameras = cameras;
  {
    SessionWriter writer(path, info, {});
    FrameSet set = test_set(cameras, 0);
    set.cameras[1].a.synchronised = false;
    set.cameras[1].b.synchronised = false;
    writer.append(set);
    writer.append(test_set(cameras, 1));
    writer.finish();
  }
  const SessionReader reader(path);
  EXPECT_EQ(reader.missing_frames(), 0);
  EXPECT_EQ(reader.incomplete_sets(), 1);
  const FrameSet back = reader.read_set(0);
  EXPECT_TRUE(back.cameras[1].a.present());
  EXPECT_FALSE(back.cameras[1].a.synchronised);
  EXPECT_FALSE(back.complete());
  EXPECT_TRUE(reader.read_set(1).complete());
  EXPECT_FALSE(reader.set_record(0).frame_synchronised[1][0]);
}

}  // namespace
}  // namespace tomorig::storage
