// Volume files: bit-identical round trips of sparse and dense volumes, the XDMF sidecar that
// ParaView reads, and clear errors for bad names, existing files and damaged files.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "storage_test_support.h"
#include "tomorig/storage/volume_file.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;
using testing::test_camera;
using testing::write_test_session;

// A sparse volume with a few hundred voxels spread over every z-slice, including the first
// and last voxel of the grid (the edges of the slice-by-slice dense export).
SparseVolume test_sparse(const VoxelGrid& grid, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.1f, 100.0f);
  SparseVolume v;
  v.grid = grid;
  for (std::size_t n = 0; n < grid.voxel_count(); n += 1 + rng() % 37) {
    v.index.push_back(static_cast<std::uint32_t>(n));
    v.intensity.push_back(value(rng));
  }
  if (v.index.back() != grid.voxel_count() - 1) {
    v.index.push_back(static_cast<std::uint32_t>(grid.voxel_count() - 1));
    v.intensity.push_back(7.5f);
  }
  return v;
}

const VoxelGrid kGrid{24, 20, 9, {-1.25, 0.5, -3.0}, 0.0195};

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(VolumeFile, SparseAndDenseRoundTripBitIdentical) {
  TempDir dir;
  const fs::path path = dir / "v.h5";
  const SparseVolume a = test_sparse(kGrid, 1);
  DenseVolume b(kGrid);
  std::mt19937 rng(2);
  for (float& x : b.values) x = static_cast<float>(rng() % 1000) * 0.25f;
  {
    VolumeFileWriter out(path, {.source_session = "s.h5", .set_index = 3, .parameters_json = R"({"mu":1})"});
    out.add("a", a, {.algorithm = "fmart", .exposure = "A", .report_json = R"({"iterations":5})"});
    out.add("b", b, {.algorithm = "truth", .exposure = "B"});
    out.finish();
  }
  EXPECT_FALSE(fs::exists(dir / "v.h5.partial"));
  VolumeFileReader in(path);
  EXPECT_EQ(in.info().source_session, "s.h5");
  EXPECT_EQ(in.info().set_index, 3u);
  EXPECT_EQ(in.info().parameters_json, R"({"mu":1})");
  ASSERT_EQ(in.volumes().size(), 2u);
  EXPECT_EQ(in.volumes()[0].name, "a");
  EXPECT_EQ(in.volumes()[1].name, "b");
  const StoredVolume& sa = in.volume("a");
  EXPECT_TRUE(sa.has_sparse);
  EXPECT_TRUE(sa.has_dense);
  EXPECT_EQ(sa.attributes.algorithm, "fmart");
  EXPECT_EQ(sa.attributes.exposure, "A");
  EXPECT_EQ(sa.attributes.report_json, R"({"iterations":5})");
  EXPECT_EQ(sa.grid.nx, kGrid.nx);
  EXPECT_EQ(sa.grid.ny, kGrid.ny);
  EXPECT_EQ(sa.grid.nz, kGrid.nz);
  EXPECT_EQ(sa.grid.origin.x, kGrid.origin.x);
  EXPECT_EQ(sa.grid.origin.z, kGrid.origin.z);
  EXPECT_EQ(sa.grid.voxel_size, kGrid.voxel_size);

  const SparseVolume a_back = in.read_sparse("a");
  EXPECT_EQ(a_back.index, a.index);
  EXPECT_EQ(a_back.intensity, a.intensity);
  // The dense export of a sparse volume holds exactly its voxels and zeros elsewhere.
  EXPECT_EQ(in.read_dense("a").values, a.to_dense().values);
  EXPECT_EQ(in.read_dense("b").values, b.values);
  // A dense-only volume reads back sparse as its non-zero voxels.
  const SparseVolume b_sparse = in.read_sparse("b");
  EXPECT_EQ(b_sparse.to_dense().values, b.values);
}

TEST(VolumeFile, XdmfSidecarPointsAtTheDenseDatasets) {
  TempDir dir;
  const fs::path path = dir / "vol.h5";
  VolumeFileWriter out(path, {});
  out.add("a", test_sparse(kGrid, 3), {.algorithm = "mlos"});
  out.finish();
  const fs::path xdmf = dir / "vol.xdmf";
  ASSERT_TRUE(fs::exists(xdmf));
  const std::string text = read_text(xdmf);
  // XDMF orders dimensions slowest first: nz ny nx; origin and spacing likewise z, y, x.
  EXPECT_NE(text.find("Dimensions=\"9 20 24\""), std::string::npos) << text;
  EXPECT_NE(text.find("vol.h5:/volumes/a/dense"), std::string::npos) << text;
  EXPECT_NE(text.find("-3 0.5 -1.25"), std::string::npos) << text;
  EXPECT_NE(text.find("0.0195 0.0195 0.0195"), std::string::npos) << text;
  EXPECT_NE(text.find("</Xdmf>"), std::string::npos);
  // The referenced dataset exists with that shape, readable by plain HDF5.
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t d = H5Dopen2(file, "/volumes/a/dense", H5P_DEFAULT);
  ASSERT_GE(d, 0);
  const hid_t space = H5Dget_space(d);
  hsize_t dims[3] = {};
  ASSERT_EQ(H5Sget_simple_extent_ndims(space), 3);
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], 9u);
  EXPECT_EQ(dims[1], 20u);
  EXPECT_EQ(dims[2], 24u);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(file);
}

TEST(VolumeFile, EmptySparseVolumeRoundTrips) {
  TempDir dir;
  SparseVolume empty;
  empty.grid = kGrid;
  VolumeFileWriter out(dir / "e.h5", {});
  out.add("a", empty, {});
  out.finish();
  VolumeFileReader in(dir / "e.h5");
  EXPECT_EQ(in.read_sparse("a").size(), 0u);
  const DenseVolume dense = in.read_dense("a");
  EXPECT_EQ(dense.values.size(), kGrid.voxel_count());
  EXPECT_EQ(std::count(dense.values.begin(), dense.values.end(), 0.0f),
            static_cast<std::ptrdiff_t>(kGrid.voxel_count()));
}

TEST(VolumeFile, SparseOnlyFileHasNoSidecar) {
  TempDir dir;
  VolumeFileWriter out(dir / "s.h5", {}, {.dense_export = false});
  out.add("a", test_sparse(kGrid, 11), {});
  out.finish();
  EXPECT_FALSE(fs::exists(dir / "s.xdmf"));
  VolumeFileReader in(dir / "s.h5");
  EXPECT_FALSE(in.volume("a").has_dense);
  EXPECT_EQ(in.read_sparse("a").index, test_sparse(kGrid, 11).index);
}

TEST(VolumeFile, AbandonedWriterLeavesNothing) {
  TempDir dir;
  { VolumeFileWriter out(dir / "v.h5", {}); out.add("a", test_sparse(kGrid, 4), {}); }
  EXPECT_FALSE(fs::exists(dir / "v.h5"));
  EXPECT_FALSE(fs::exists(dir / "v.h5.partial"));
  EXPECT_FALSE(fs::exists(dir / "v.xdmf"));
}

TEST(VolumeFileErrors, ExistingFileIsNotReplacedWithoutOverwrite) {
  TempDir dir;
  { std::ofstream(dir / "v.h5") << "keep me"; }
  expect_error([&] { VolumeFileWriter out(dir / "v.h5", {}); }, ErrorKind::bad_input, {"already exists", "--overwrite"});
  EXPECT_EQ(read_text(dir / "v.h5"), "keep me");
  VolumeFileWriter out(dir / "v.h5", {}, {.overwrite = true});
  out.add("a", test_sparse(kGrid, 5), {});
  out.finish();
  EXPECT_EQ(VolumeFileReader(dir / "v.h5").volumes().size(), 1u);
}

TEST(VolumeFileErrors, BadNamesAndDuplicates) {
  TempDir dir;
  VolumeFileWriter out(dir / "v.h5", {});
  const SparseVolume v = test_sparse(kGrid, 6);
  expect_error([&] { out.add("a/b", v, {}); }, ErrorKind::bad_input, {"'a/b' is not allowed"});
  expect_error([&] { out.add("", v, {}); }, ErrorKind::bad_input, {"is not allowed"});
  out.add("a", v, {});
  expect_error([&] { out.add("a", v, {}); }, ErrorKind::bad_input, {"'a' is added twice"});
  SparseVolume unsorted = v;
  std::swap(unsorted.index[0], unsorted.index[1]);
  expect_error([&] { out.add("u", unsorted, {}); }, ErrorKind::bad_input, {"ascending"});
}

TEST(VolumeFileErrors, MissingFolder) {
  TempDir dir;
  expect_error([&] { VolumeFileWriter out(dir / "no" / "v.h5", {}); }, ErrorKind::bad_input, {"does not exist"});
}

TEST(VolumeFileErrors, TruncatedFile) {
  TempDir dir;
  const fs::path path = dir / "v.h5";
  {
    VolumeFileWriter out(path, {});
    out.add("a", test_sparse(kGrid, 7), {});
    out.finish();
  }
  fs::resize_file(path, fs::file_size(path) / 3);
  expect_error([&] { VolumeFileReader in(path); }, ErrorKind::bad_input, {path.string(), "corrupt or truncated"});
}

TEST(VolumeFileErrors, SessionFileIsNotAVolumeFile) {
  TempDir dir;
  write_test_session(dir / "s.h5", {test_camera("cam0", 8, 6, PixelFormat::Mono8)}, 1);
  expect_error([&] { VolumeFileReader in(dir / "s.h5"); }, ErrorKind::bad_input,
               {"not a valid tomorig volume file", "tomorig inspect"});
}

TEST(VolumeFileErrors, UnknownVolumeNameListsTheStoredOnes) {
  TempDir dir;
  VolumeFileWriter out(dir / "v.h5", {});
  out.add("a", test_sparse(kGrid, 8), {});
  out.add("b", test_sparse(kGrid, 9), {});
  out.finish();
  VolumeFileReader in(dir / "v.h5");
  expect_error([&] { in.read_dense("c"); }, ErrorKind::bad_input, {"no volume 'c'", "a, b"});
}

}  // namespace
}  // namespace tomorig::storage
