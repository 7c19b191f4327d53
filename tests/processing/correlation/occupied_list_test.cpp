// The occupied-voxel lists of the direct correlation (list_occupied) against a plain scan of
// the same volume written here: every voxel whose magnitude exceeds the threshold, in block
// scan order, by row, and on the block faces. The listing tests rows 16 voxels at a time and
// skips empty chunks, so the volume has rows that are not a multiple of 16 long, voxels in the
// last partial chunk, negative values, and values exactly at the threshold (not listed).
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "correlation/direct_correlator.h"

namespace {

using tomorig::piv::detail::Int3;
using tomorig::piv::detail::list_occupied;
using tomorig::piv::detail::OccupiedVoxels;
using tomorig::piv::detail::VolumeView;

struct Volume {
  int nx, ny, nz;
  std::vector<float> values;
  VolumeView view() const { return {values.data(), nx, ny, nz}; }
  float at(int x, int y, int z) const { return values[x + static_cast<std::size_t>(nx) * (y + static_cast<std::size_t>(ny) * z)]; }
};

// Sparse particle-like values: most voxels 0, some faint, some bright, a few negative, a few
// exactly at the threshold, and the last voxel of every tenth row set (the partial chunk).
Volume make_volume(int nx, int ny, int nz, float threshold_value, unsigned seed) {
  Volume v{nx, ny, nz, std::vector<float>(static_cast<std::size_t>(nx) * ny * nz, 0.0f)};
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (float& value : v.values) {
    const float u = uniform(random);
    if (u < 0.03f) value = 0.1f + uniform(random);                  // bright
    else if (u < 0.05f) value = threshold_value * uniform(random);  // below the threshold
    else if (u < 0.055f) value = -(0.1f + uniform(random));         // negative, bright
    else if (u < 0.057f) value = threshold_value;                   // exactly at it
  }
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; y += 10) v.values[(nx - 1) + static_cast<std::size_t>(nx) * (y + static_cast<std::size_t>(ny) * z)] = 0.5f;
  v.values[0] = 1.2f;  // the largest magnitude, known
  return v;
}

void expect_lists_match_a_plain_scan(int nx, int ny, int nz, Int3 block) {
  constexpr float relative = 3e-3f;
  const float largest = 1.2f, threshold = relative * largest;
  const Volume v = make_volume(nx, ny, nz, threshold, 7u + nx);
  OccupiedVoxels o;
  list_occupied(v.view(), block, relative, tomorig::piv::detail::largest_magnitude(v.view(), 2), 2, o, true);

  const Int3 blocks{(nx + block.x - 1) / block.x, (ny + block.y - 1) / block.y, (nz + block.z - 1) / block.z};
  ASSERT_EQ(o.blocks.x, blocks.x);
  ASSERT_EQ(o.blocks.y, blocks.y);
  ASSERT_EQ(o.blocks.z, blocks.z);
  std::size_t listed = 0;
  for (int bz = 0; bz < blocks.z; ++bz)
    for (int by = 0; by < blocks.y; ++by)
      for (int bx = 0; bx < blocks.x; ++bx) {
        const std::size_t b = bx + static_cast<std::size_t>(blocks.x) * (by + static_cast<std::size_t>(blocks.y) * bz);
        std::vector<OccupiedVoxels::Entry> want, faces[6];
        for (int z = bz * block.z; z < std::min(nz, (bz + 1) * block.z); ++z)
          for (int y = by * block.y; y < std::min(ny, (by + 1) * block.y); ++y)
            for (int x = bx * block.x; x < std::min(nx, (bx + 1) * block.x); ++x)
              if (std::abs(v.at(x, y, z)) > threshold) {
                const OccupiedVoxels::Entry e{static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                                              static_cast<std::uint16_t>(z), v.at(x, y, z)};
                want.push_back(e);
                const bool on[6] = {x % block.x == 0, x % block.x == block.x - 1, y % block.y == 0,
                                    y % block.y == block.y - 1, z % block.z == 0, z % block.z == block.z - 1};
                for (int f = 0; f < 6; ++f)
                  if (on[f]) faces[f].push_back(e);
              }
        ASSERT_EQ(o.offsets[b + 1] - o.offsets[b], want.size()) << "block " << bx << "," << by << "," << bz;
        for (std::size_t n = 0; n < want.size(); ++n) {
          const OccupiedVoxels::Entry& got = o.entries[o.offsets[b] + n];
          EXPECT_EQ(got.x, want[n].x);
          EXPECT_EQ(got.y, want[n].y);
          EXPECT_EQ(got.z, want[n].z);
          EXPECT_EQ(got.value, want[n].value);
        }
        for (int f = 0; f < 6; ++f) {
          ASSERT_EQ(o.face_offsets[f][b + 1] - o.face_offsets[f][b], faces[f].size()) << "face " << f;
          for (std::size_t n = 0; n < faces[f].size(); ++n) {
            EXPECT_EQ(o.face_entries[f][o.face_offsets[f][b] + n].x, faces[f][n].x);
            EXPECT_EQ(o.face_entries[f][o.face_offsets[f][b] + n].y, faces[f][n].y);
            EXPECT_EQ(o.face_entries[f][o.face_offsets[f][b] + n].z, faces[f][n].z);
          }
        }
        listed += want.size();
      }
  EXPECT_EQ(o.entries.size(), listed);
  EXPECT_GT(listed, 0u);
  EXPECT_DOUBLE_EQ(o.occupied_fraction, static_cast<double>(listed) / (static_cast<double>(nx) * ny * nz));
  // By row: x ascending, every listed voxel of the row and nothing else.
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y) {
      const std::size_t r = y + static_cast<std::size_t>(ny) * z;
      std::vector<int> want;
      for (int x = 0; x < nx; ++x)
        if (std::abs(v.at(x, y, z)) > threshold) want.push_back(x);
      ASSERT_EQ(o.row_offsets[r + 1] - o.row_offsets[r], want.size()) << "row " << y << "," << z;
      for (std::size_t n = 0; n < want.size(); ++n) {
        EXPECT_EQ(o.row_entries[o.row_offsets[r] + n].x, want[n]);
        EXPECT_EQ(o.row_entries[o.row_offsets[r] + n].value, v.at(want[n], y, z));
      }
    }
}

TEST(OccupiedList, MatchesAPlainScanWithRowsNotAMultipleOfTheChunk) { expect_lists_match_a_plain_scan(37, 11, 9, {5, 4, 3}); }

TEST(OccupiedList, MatchesAPlainScanWithWholeChunksAndTheWindowStepAsBlock) {
  expect_lists_match_a_plain_scan(64, 24, 16, {8, 8, 8});
}

TEST(OccupiedList, MatchesAPlainScanOnRowsShorterThanOneChunk) { expect_lists_match_a_plain_scan(7, 5, 4, {2, 2, 2}); }

}  // namespace
