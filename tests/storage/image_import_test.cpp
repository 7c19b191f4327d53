// Importing image sequences: the fluidimage sample, pairing rules, multi-page TIFF, and the
// errors for sequences that do not fit together.
#include <gtest/gtest.h>

#include "real_data.h"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "storage_test_support.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/image_import.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;

// A deterministic single-channel image; `seed` makes frames distinguishable.
cv::Mat pattern(int width, int height, int cv_type, int seed) {
  cv::Mat m(height, width, cv_type);
  cv::randu(m, cv::Scalar(0), cv::Scalar(cv_type == CV_8UC1 ? 256 : 65536));
  m.ptr(0)[0] = static_cast<std::uint8_t>(seed);  // first byte differs per frame
  return m;
}

void write_png(const fs::path& file, const cv::Mat& m) {
  fs::create_directories(file.parent_path());
  ASSERT_TRUE(cv::imwrite(file.string(), m)) << file;
}

// Numbered file names. GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
std::string numbered(const char* prefix, int i, const char* extension) {
  std::string name(prefix);
  name += std::to_string(i);
  name += extension;
  return name;
}

bool same_pixels(const Image& image, const cv::Mat& m) {
  if (image.width() != m.cols || image.height() != m.rows) return false;
  const int cv_type = image.type() == SampleType::u8 ? CV_8UC1 : CV_16UC1;
  if (m.type() != cv_type) return false;
  for (int y = 0; y < m.rows; ++y)
    if (std::memcmp(image.data() + y * image.stride_bytes(), m.ptr(y), image.row_bytes()) != 0) return false;
  return true;
}

// Two cameras x `sets` sets of PNG files named im0000Na.png / im0000Nb.png.
void write_png_sequence(const TempDir& dir, const std::string& cam, int sets, int width, int height, int cv_type) {
  for (int s = 1; s <= sets; ++s)
    for (char e : {'a', 'b'}) {
      char name[32];
      std::snprintf(name, sizeof name, "im%05d%c.png", s, e);
      write_png(dir / cam / name, pattern(width, height, cv_type, s * 2 + (e == 'b')));
    }
}

ImportOptions options_for(const TempDir& dir, const std::vector<std::string>& cams, const std::string& glob) {
  ImportOptions o;
  for (const auto& c : cams) o.cameras.push_back({c, (dir / c / glob).string(), std::nullopt, 0.0});
  o.dt_us = 100;
  return o;
}

TEST(ImageImport, FluidimageTomoPivSample) {
  const fs::path root = fs::path(TOMORIG_SHARED_DIR) / "data" / "fluidimage-tomopiv" / "particle";
  TOMORIG_NEED_REAL_DATA(root / "cam0.pre" / "im00001a.tif");
  TempDir dir;
  ImportOptions o;
  for (int c = 0; c < 4; ++c) {
    const std::string id = "cam" + std::to_string(c);
    o.cameras.push_back({id, (root / (id + ".pre") / "im*.tif").string(), std::nullopt, 7.4});
  }
  o.dt_us = 250;
  const ImportResult result = import_images(o, dir / "tomopiv.h5");
  EXPECT_EQ(result.plan.pairing, FramePairing::by_name);
  EXPECT_EQ(result.sets, 1u);

  SessionReader reader(dir / "tomopiv.h5");
  ASSERT_EQ(reader.info().cameras.size(), 4u);
  ASSERT_EQ(reader.set_count(), 1u);
  const FrameSet set = reader.read_set(0);
  EXPECT_EQ(set.dt_ns, 250'000);
  EXPECT_EQ(set.cameras[0].b.timestamp_ns - set.cameras[0].a.timestamp_ns, 250'000);
  for (int c = 0; c < 4; ++c) {
    const std::string id = "cam" + std::to_string(c);
    const SessionCamera& cam = reader.info().cameras[static_cast<std::size_t>(c)];
    EXPECT_EQ(cam.id, id);
    EXPECT_EQ(cam.pixel_format, PixelFormat::Mono8);
    EXPECT_EQ(cam.pixel_pitch_um, 7.4);
    for (char e : {'a', 'b'}) {
      const cv::Mat source =
          cv::imread((root / (id + ".pre") / (std::string("im00001") + e + ".tif")).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(source.empty());
      EXPECT_EQ(cam.width, source.cols);
      EXPECT_EQ(cam.height, source.rows);
      const Frame& frame = e == 'a' ? set.cameras[static_cast<std::size_t>(c)].a : set.cameras[static_cast<std::size_t>(c)].b;
      EXPECT_TRUE(same_pixels(frame.image, source)) << id << " " << e;
    }
  }
  // The README says 500 x 504; whichever way round, both cameras agree with the files above.
  EXPECT_EQ(reader.info().cameras[0].width * reader.info().cameras[0].height, 500 * 504);
}

TEST(ImageImport, PngSequencesPairedByName16Bit) {
  TempDir dir;
  write_png_sequence(dir, "cam0", 3, 40, 30, CV_16UC1);
  write_png_sequence(dir, "cam1", 3, 40, 30, CV_16UC1);
  ImportOptions o = options_for(dir, {"cam0", "cam1"}, "im*.png");
  o.cameras[1].pixel_format = PixelFormat::Mono12;
  o.rate_hz = 10;
  o.rig_config_toml = "name = \"imported\"\n";
  const ImportResult result = import_images(o, dir / "s.h5");
  EXPECT_EQ(result.sets, 3u);

  SessionReader reader(dir / "s.h5");
  EXPECT_EQ(reader.info().cameras[0].pixel_format, PixelFormat::Mono16);
  EXPECT_EQ(reader.info().cameras[1].pixel_format, PixelFormat::Mono12);
  EXPECT_EQ(reader.info().rig_config_toml, o.rig_config_toml);
  const FrameSet set = reader.read_set(2);
  EXPECT_EQ(set.trigger_timestamp_ns, 200'000'000);
  EXPECT_EQ(set.trigger_index, 2u);
  EXPECT_TRUE(same_pixels(set.cameras[1].b.image,
                          cv::imread((dir / "cam1" / "im00003b.png").string(), cv::IMREAD_UNCHANGED)));
}

TEST(ImageImport, PairsByOrderInNaturalOrder) {
  TempDir dir;
  // frame1..frame10: lexical order would put frame10 second.
  std::vector<cv::Mat> frames;
  for (int i = 1; i <= 10; ++i) {
    frames.push_back(pattern(16, 8, CV_8UC1, i));
    write_png(dir / "cam0" / numbered("frame", i, ".png"), frames.back());
  }
  ImportOptions o = options_for(dir, {"cam0"}, "frame*.png");
  const ImportResult result = import_images(o, dir / "s.h5");
  EXPECT_EQ(result.plan.pairing, FramePairing::by_order);  // names do not end in a/b
  SessionReader reader(dir / "s.h5");
  ASSERT_EQ(reader.set_count(), 5u);
  for (std::uint64_t s = 0; s < 5; ++s) {
    const FrameSet set = reader.read_set(s);
    EXPECT_TRUE(same_pixels(set.cameras[0].a.image, frames[2 * s])) << s;
    EXPECT_TRUE(same_pixels(set.cameras[0].b.image, frames[2 * s + 1])) << s;
  }
}

TEST(ImageImport, MultiPageTiff) {
  TempDir dir;
  std::vector<cv::Mat> pages;
  for (int i = 0; i < 6; ++i) pages.push_back(pattern(24, 20, CV_16UC1, i));
  fs::create_directories(dir / "cam0");
  ASSERT_TRUE(cv::imwritemulti((dir / "cam0" / "run.tif").string(), pages));
  // A second camera as a single-page sequence of the same frames.
  for (int i = 0; i < 6; ++i) write_png(dir / "cam1" / numbered("f", i, ".png"), pages[5 - i]);
  EXPECT_EQ(image_page_count(dir / "cam0" / "run.tif"), 6);

  ImportOptions o;
  o.cameras = {{"cam0", (dir / "cam0" / "run.tif").string(), std::nullopt, 0.0},
               {"cam1", (dir / "cam1" / "f*.png").string(), std::nullopt, 0.0}};
  o.pairing = FramePairing::by_order;
  o.writer.compression = Compression::bitshuffle_lz4;
  import_images(o, dir / "s.h5");

  SessionReader reader(dir / "s.h5");
  ASSERT_EQ(reader.set_count(), 3u);
  for (std::uint64_t s = 0; s < 3; ++s) {
    const FrameSet set = reader.read_set(s);
    EXPECT_TRUE(same_pixels(set.cameras[0].a.image, pages[2 * s])) << s;
    EXPECT_TRUE(same_pixels(set.cameras[0].b.image, pages[2 * s + 1])) << s;
    EXPECT_TRUE(same_pixels(set.cameras[1].a.image, pages[5 - 2 * s])) << s;
  }
}

TEST(ImageImport, DifferentSetCountsAcrossCamerasNameTheFile) {
  TempDir dir;
  write_png_sequence(dir, "cam0", 1, 16, 8, CV_8UC1);
  write_png_sequence(dir, "cam1", 2, 16, 8, CV_8UC1);
  const ImportOptions o = options_for(dir, {"cam0", "cam1"}, "*.png");
  expect_error([&] { import_images(o, dir / "s.h5"); }, ErrorKind::bad_input,
               {"same number of sets", (dir / "cam1" / "im00002a.png").string()});
  EXPECT_FALSE(fs::exists(dir / "s.h5"));
  EXPECT_FALSE(fs::exists(dir / "s.h5.partial"));
}

TEST(ImageImport, DifferentSizesAcrossCamerasNameTheFile) {
  TempDir dir;
  write_png_sequence(dir, "cam0", 2, 16, 8, CV_8UC1);
  write_png_sequence(dir, "cam1", 2, 16, 9, CV_8UC1);
  const ImportOptions o = options_for(dir, {"cam0", "cam1"}, "*.png");
  expect_error([&] { import_images(o, dir / "s.h5"); }, ErrorKind::bad_input,
               {(dir / "cam1" / "im00001a.png").string(), "16 x 9", "16 x 8", "same size"});
  EXPECT_FALSE(fs::exists(dir / "s.h5"));
  EXPECT_FALSE(fs::exists(dir / "s.h5.partial"));
}

TEST(ImageImport, SizeChangeLaterInTheSequenceLeavesNothingBehind) {
  TempDir dir;
  write_png_sequence(dir, "cam0", 3, 16, 8, CV_8UC1);
  write_png(dir / "cam0" / "im00003b.png", pattern(17, 8, CV_8UC1, 1));  // overwrite the last frame
  const ImportOptions o = options_for(dir, {"cam0"}, "*.png");
  expect_error([&] { import_images(o, dir / "s.h5"); }, ErrorKind::bad_input,
               {(dir / "cam0" / "im00003b.png").string(), "17 x 8"});
  EXPECT_FALSE(fs::exists(dir / "s.h5"));
  EXPECT_FALSE(fs::exists(dir / "s.h5.partial"));
}

TEST(ImageImport, SampleTypeChangeWithinACamera) {
  TempDir dir;
  write_png_sequence(dir, "cam0", 2, 16, 8, CV_8UC1);
  write_png(dir / "cam0" / "im00002a.png", pattern(16, 8, CV_16UC1, 1));
  const ImportOptions o = options_for(dir, {"cam0"}, "*.png");
  expect_error([&] { import_images(o, dir / "s.h5"); }, ErrorKind::bad_input,
               {(dir / "cam0" / "im00002a.png").string(), "uint16", "uint8"});
}

TEST(ImageImport, MissingPartnerByName) {
  TempDir dir;
  write_png_sequence(dir, "cam0", 2, 16, 8, CV_8UC1);
  fs::remove(dir / "cam0" / "im00002b.png");
  const ImportOptions o = options_for(dir, {"cam0"}, "*.png");
  expect_error([&] { plan_image_import(o); }, ErrorKind::bad_input,
               {(dir / "cam0" / "im00002a.png").string(), "no partner", "im00002b.png"});
}

TEST(ImageImport, OddFrameCountByOrder) {
  TempDir dir;
  for (int i = 0; i < 3; ++i) write_png(dir / "cam0" / numbered("f", i, ".png"), pattern(8, 8, CV_8UC1, i));
  const ImportOptions o = options_for(dir, {"cam0"}, "*.png");
  expect_error([&] { plan_image_import(o); }, ErrorKind::bad_input, {"odd", (dir / "cam0" / "f2.png").string()});
}

TEST(ImageImport, NameRulesAndPatternErrors) {
  TempDir dir;
  write_png(dir / "cam0" / "frame1.png", pattern(8, 8, CV_8UC1, 0));
  write_png(dir / "cam0" / "frame2.png", pattern(8, 8, CV_8UC1, 0));
  ImportOptions o = options_for(dir, {"cam0"}, "*.png");
  o.pairing = FramePairing::by_name;
  expect_error([&] { plan_image_import(o); }, ErrorKind::bad_input,
               {(dir / "cam0" / "frame1.png").string(), "'a' or 'b'"});
  o = options_for(dir, {"cam0"}, "*.tif");
  expect_error([&] { plan_image_import(o); }, ErrorKind::bad_input, {"cam0", "no files match", "*.tif"});
  o = options_for(dir, {"cam0", "cam0"}, "*.png");
  expect_error([&] { plan_image_import(o); }, ErrorKind::bad_input, {"cam0", "twice"});
  expect_error([&] { plan_image_import(ImportOptions{}); }, ErrorKind::bad_input, {"at least one camera"});
}

TEST(ImageImport, RejectsColourAndNonImages) {
  TempDir dir;
  write_png(dir / "rgb" / "ima.png", cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
  write_png(dir / "rgb" / "imb.png", cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
  ImportOptions o = options_for(dir, {"rgb"}, "*.png");
  expect_error([&] { import_images(o, dir / "s.h5"); }, ErrorKind::bad_input,
               {(dir / "rgb" / "ima.png").string(), "3 channel(s)"});
  fs::create_directories(dir / "txt");
  std::ofstream(dir / "txt" / "notes.png") << "not a png";
  std::ofstream(dir / "txt" / "notes2.png") << "not a png";
  o = options_for(dir, {"txt"}, "*.png");
  expect_error([&] { plan_image_import(o); }, ErrorKind::bad_input, {(dir / "txt" / "notes.png").string()});
}

TEST(ImageImport, PixelFormatMustFitTheSamples) {
  TempDir dir;
  write_png_sequence(dir, "cam0", 1, 16, 8, CV_8UC1);
  ImportOptions o = options_for(dir, {"cam0"}, "*.png");
  o.cameras[0].pixel_format = PixelFormat::Mono16;
  expect_error([&] { import_images(o, dir / "s.h5"); }, ErrorKind::bad_input, {"cam0", "Mono16", "uint8"});
  o.cameras[0].pixel_format.reset();
  o.dt_us = -1;
  expect_error([&] { import_images(o, dir / "s.h5"); }, ErrorKind::bad_input, {"dt"});
}

TEST(ImageImport, PairingNames) {
  for (FramePairing p : {FramePairing::automatic, FramePairing::by_name, FramePairing::by_order})
    EXPECT_EQ(parse_frame_pairing(to_string(p)), p);
  EXPECT_FALSE(parse_frame_pairing("alphabetical").has_value());
}

}  // namespace
}  // namespace tomorig::storage
