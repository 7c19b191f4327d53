// Quick-look numbers stored with a session (/quicklook): written from another thread while the
// recorder appends sets, complete after finish, absent from sessions without a quick-look,
// refused for the wrong camera count. (Reading them from a growing file, in another process,
// is tested through `tomorig inspect` in tests/apps.)
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include <hdf5.h>

#include "storage_test_support.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;
using testing::test_camera;
using testing::test_set;

// Raw HDF5 reads, to check the layout docs/file-formats.md promises to h5py and MATLAB users.
namespace h5test {
bool link_exists(const fs::path& file, const char* path) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const bool exists = H5Lexists(f, path, H5P_DEFAULT) > 0;
  H5Fclose(f);
  return exists;
}
std::vector<unsigned long long> dims(const fs::path& file, const char* path) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  std::vector<hsize_t> out(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, out.data(), nullptr);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
  return {out.begin(), out.end()};
}
// Reads a string-list attribute the way an outside tool would, whether its strings are stored
// fixed-length (format-2 session files) or variable-length.
std::vector<std::string> string_list_attribute(const fs::path& file, const char* path, const char* name) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
  const hid_t a = H5Aopen(d, name, H5P_DEFAULT);
  const hid_t space = H5Aget_space(a);
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space, &n, nullptr);
  const hid_t stored = H5Aget_type(a);
  std::vector<std::string> out;
  if (H5Tis_variable_str(stored) > 0) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    std::vector<char*> raw(n);
    H5Aread(a, type, raw.data());
    for (char* p : raw) out.emplace_back(p != nullptr ? p : "");
    H5Dvlen_reclaim(type, space, H5P_DEFAULT, raw.data());
    H5Tclose(type);
  } else {
    const std::size_t width = H5Tget_size(stored);
    std::vector<char> raw(n * width);
    H5Aread(a, stored, raw.data());
    for (hsize_t i = 0; i < n; ++i) {
      std::string value(raw.data() + i * width, width);
      value.erase(value.find_last_not_of(std::string("\0 ", 2)) + 1);
      out.push_back(value);
    }
  }
  H5Tclose(stored);
  H5Sclose(space);
  H5Aclose(a);
  H5Dclose(d);
  H5Fclose(f);
  return out;
}
}  // namespace h5test

const std::vector<SessionCamera> kCameras{test_camera("cam0", 32, 24, PixelFormat::Mono16),
                                          test_camera("cam1", 32, 24, PixelFormat::Mono16),
                                          test_camera("cam2", 16, 12, PixelFormat::Mono8)};

SessionInfo info() {
  SessionInfo i;
  i.cameras = kCameras;
  return i;
}

// Figures that tell every field, set and camera apart.
QuickLookRecord record_for(std::uint64_t set) {
  QuickLookRecord r;
  r.set_index = set;
  r.flag = static_cast<std::uint8_t>(set % 3);
  r.preview = set % 2 == 0;
  if (r.preview) {
    r.sheet_position_mm = 0.01f * static_cast<float>(set);
    r.sheet_thickness_mm = 3.0f + 0.001f * static_cast<float>(set);
    r.ghost_front = 0.3f;
    r.ghost_back = 0.35f;
    r.rsnr = 2.5f;
  }
  r.drift_alarms = static_cast<std::uint16_t>(set % 4);
  for (std::size_t c = 0; c < kCameras.size(); ++c) {
    QuickLookCameraRecord cam;
    const float base = static_cast<float>(set * 10 + c);
    cam.flag = static_cast<std::uint8_t>((set + c) % 3);
    cam.ppp[0] = 0.05f + base * 1e-5f;
    cam.ppp[1] = 0.051f + base * 1e-5f;
    cam.diameter_px[0] = 2.5f;
    cam.diameter_px[1] = 2.6f;
    cam.source_density[0] = 0.2f;
    cam.saturated_fraction[1] = 1e-4f;
    cam.background[0] = 100 + base;
    cam.noise[1] = 3.5f;
    cam.soft_tile_fraction[0] = 0.05f;
    cam.energy_balance = 1.01f;
    cam.dt_displacement_px = 6.0f + base * 0.1f;
    cam.dt_valid_fraction = 0.9f;
    if (c == 1) cam.drift_px = 0.12f;
    r.cameras.push_back(cam);
  }
  return r;
}

void expect_same(const QuickLookRecord& got, const QuickLookRecord& want) {
  auto same = [](float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; };
  EXPECT_EQ(got.set_index, want.set_index);
  EXPECT_EQ(got.flag, want.flag);
  EXPECT_EQ(got.preview, want.preview);
  EXPECT_TRUE(same(got.sheet_position_mm, want.sheet_position_mm)) << got.sheet_position_mm;
  EXPECT_TRUE(same(got.sheet_thickness_mm, want.sheet_thickness_mm));
  EXPECT_TRUE(same(got.ghost_front, want.ghost_front));
  EXPECT_TRUE(same(got.rsnr, want.rsnr));
  EXPECT_EQ(got.drift_alarms, want.drift_alarms);
  ASSERT_EQ(got.cameras.size(), want.cameras.size());
  for (std::size_t c = 0; c < want.cameras.size(); ++c) {
    const auto& g = got.cameras[c];
    const auto& w = want.cameras[c];
    EXPECT_EQ(g.flag, w.flag);
    for (int e = 0; e < 2; ++e) {
      EXPECT_TRUE(same(g.ppp[e], w.ppp[e]));
      EXPECT_TRUE(same(g.diameter_px[e], w.diameter_px[e]));
      EXPECT_TRUE(same(g.source_density[e], w.source_density[e]));
      EXPECT_TRUE(same(g.saturated_fraction[e], w.saturated_fraction[e]));
      EXPECT_TRUE(same(g.background[e], w.background[e]));
      EXPECT_TRUE(same(g.noise[e], w.noise[e]));
      EXPECT_TRUE(same(g.soft_tile_fraction[e], w.soft_tile_fraction[e]));
    }
    EXPECT_TRUE(same(g.energy_balance, w.energy_balance));
    EXPECT_TRUE(same(g.dt_displacement_px, w.dt_displacement_px));
    EXPECT_TRUE(same(g.dt_valid_fraction, w.dt_valid_fraction));
    EXPECT_TRUE(same(g.drift_px, w.drift_px));
  }
}

TEST(QuickLookStorage, LiveRecordingTakesRowsFromAnotherThreadWhileSetsAreAppended) {
  TempDir dir;
  const fs::path path = dir.path() / "live.h5";
  SessionWriterOptions options;
  options.live = true;
  options.flush.every_sets = 1;
  SessionWriter writer(path, info(), options);

  constexpr std::uint64_t kSets = 60;
  // The quick-look thread stores every other set (it skips to stay current), racing the
  // recorder's appends.
  std::thread quicklook([&] {
    for (std::uint64_t k = 0; k < kSets; k += 2) writer.append_quicklook(record_for(k));
  });
  for (std::uint64_t k = 0; k < kSets; ++k) writer.append(test_set(kCameras, k));
  quicklook.join();

  writer.finish();
  const SessionReader reader(path);
  EXPECT_EQ(reader.set_count(), kSets);
  const auto rows = reader.quicklook();
  ASSERT_EQ(rows.size(), kSets / 2);
  for (std::size_t r = 0; r < rows.size(); ++r) expect_same(rows[r], record_for(2 * r));
}

TEST(QuickLookStorage, OneGoWriterCreatesTheTablesOnFirstUseAndOlderSessionsHaveNone) {
  TempDir dir;
  const fs::path with = dir.path() / "with.h5", without = dir.path() / "without.h5";
  {
    SessionWriter writer(with, info());
    writer.append(test_set(kCameras, 0));
    writer.append_quicklook(record_for(7));  // out of order, not the set just written: fine
    writer.append_quicklook(record_for(0));
    writer.finish();
  }
  {
    SessionWriter writer(without, info());
    writer.append(test_set(kCameras, 0));
    writer.finish();
  }
  const auto rows = SessionReader(with).quicklook();
  ASSERT_EQ(rows.size(), 2u) << "one record per set, in set order";
  expect_same(rows[0], record_for(0));
  expect_same(rows[1], record_for(7));
  EXPECT_TRUE(SessionReader(without).quicklook().empty());
  EXPECT_FALSE(h5test::link_exists(without, "/quicklook")) << "no empty tables in sessions without a quick-look";
}

TEST(QuickLookStorage, RowsOfTheSameSetAreMerged) {
  TempDir dir;
  const fs::path path = dir.path() / "s.h5";
  SessionWriter writer(path, info());
  writer.append(test_set(kCameras, 0));
  // Statistics first (no preview), the preview volume and drift of the same set later.
  QuickLookRecord statistics = record_for(1);
  statistics.flag = 0;
  QuickLookRecord preview;
  preview.set_index = 1;
  preview.flag = 1;
  preview.preview = true;
  preview.sheet_position_mm = 0.25f;
  preview.sheet_thickness_mm = 2.9f;
  preview.drift_alarms = 2;
  preview.cameras.resize(kCameras.size());
  for (auto& c : preview.cameras) c.flag = 0;
  preview.cameras[2].flag = 2;
  preview.cameras[2].drift_px = 0.45f;
  writer.append_quicklook(statistics);
  writer.append_quicklook(record_for(4));
  writer.append_quicklook(preview);
  writer.finish();
  const auto rows = SessionReader(path).quicklook();
  ASSERT_EQ(rows.size(), 2u);
  const QuickLookRecord& merged = rows[0];
  EXPECT_EQ(merged.set_index, 1u);
  EXPECT_EQ(merged.flag, 1) << "the worse of green and amber";
  EXPECT_TRUE(merged.preview);
  EXPECT_FLOAT_EQ(merged.sheet_position_mm, 0.25f);
  EXPECT_EQ(merged.drift_alarms, 2);
  EXPECT_FLOAT_EQ(merged.cameras[0].ppp[0], statistics.cameras[0].ppp[0]) << "statistics kept";
  EXPECT_FLOAT_EQ(merged.cameras[2].drift_px, 0.45f);
  EXPECT_EQ(merged.cameras[2].flag, 2);
  EXPECT_FLOAT_EQ(merged.cameras[1].drift_px, 0.12f) << "a later unmeasured figure does not erase an earlier one";
  expect_same(rows[1], record_for(4));
}

TEST(QuickLookStorage, TablesCarryTheirColumnNames) {
  TempDir dir;
  const fs::path path = dir.path() / "s.h5";
  SessionWriter writer(path, info());
  writer.append(test_set(kCameras, 0));
  writer.append_quicklook(record_for(0));
  writer.finish();
  const auto names = h5test::string_list_attribute(path, "/quicklook/cameras", "columns");
  ASSERT_EQ(names.size(), quicklook_camera_columns().size());
  EXPECT_EQ(names[1], "ppp_a");
  EXPECT_EQ(h5test::dims(path, "/quicklook/cameras"),
            (std::vector<unsigned long long>{1, kCameras.size(), quicklook_camera_columns().size()}));
  EXPECT_EQ(h5test::string_list_attribute(path, "/quicklook/sets", "columns")[2], "sheet_position_mm");
}

TEST(QuickLookStorage, WrongCameraCountIsRefusedAndLosesNothing) {
  TempDir dir;
  const fs::path path = dir.path() / "s.h5";
  SessionWriter writer(path, info());
  writer.append(test_set(kCameras, 0));
  QuickLookRecord bad = record_for(0);
  bad.cameras.pop_back();
  try {
    writer.append_quicklook(bad);
    FAIL() << "accepted 2 cameras for a 3-camera session";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("2 cameras but session"), std::string::npos) << e.what();
  }
  writer.append_quicklook(record_for(0));
  writer.finish();
  EXPECT_EQ(SessionReader(path).quicklook().size(), 1u);
  EXPECT_EQ(SessionReader(path).set_count(), 1u);
}

TEST(PngInMemory, RoundTripsAndRefusesWhatIsNotAPng) {
  for (const SampleType type : {SampleType::u8, SampleType::u16}) {
    const Image image = testing::test_image(37, 21, type, 5);
    const std::string bytes = encode_png(image);
    EXPECT_EQ(bytes.substr(1, 3), "PNG");
    EXPECT_TRUE(decode_png(bytes).same_pixels(image));
  }
  EXPECT_THROW(encode_png(Image::allocate(4, 4, SampleType::f32)), Error);
  try {
    decode_png("not a png", "thumbnail 'cam0/a'");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("thumbnail 'cam0/a'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(decode_png(""), Error);
}

}  // namespace
}  // namespace tomorig::storage
