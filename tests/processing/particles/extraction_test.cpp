// Particle extraction against known blobs: sub-voxel centroids, splitting of touching
// particles, blob size and intensity, thresholds, dense = sparse, 1 thread = N threads.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/particles/extraction.h"
#include "tomorig/processing/particles/sparsify.h"
#include "tomorig/simulators/truth_volume.h"

namespace {

using tomorig::DenseVolume;
using tomorig::SparseVolume;
using tomorig::Vec3d;
using tomorig::VoxelGrid;
using tomorig::particles::ExtractionOptions;
using tomorig::particles::extract_particles;
using tomorig::particles::Particle;

VoxelGrid grid(int nx, int ny, int nz) { return VoxelGrid::centred(nx, ny, nz, 0.0195); }

// Blobs (peak 1, sigma 0.75 voxel) at continuous voxel positions.
SparseVolume blobs(const VoxelGrid& g, const std::vector<Vec3d>& voxels, double peak = 1.0) {
  std::vector<Vec3d> world;
  for (const Vec3d& v : voxels) world.push_back(g.centre_of(v.x, v.y, v.z));
  tomorig::sim::TruthVolumeOptions opt;
  opt.peak = peak;
  return tomorig::sim::truth_volume(g, world, opt);
}

SparseVolume add(const SparseVolume& a, const SparseVolume& b) {
  DenseVolume d = a.to_dense();
  for (std::size_t n = 0; n < b.size(); ++n) d.values[b.index[n]] += b.intensity[n];
  return tomorig::particles::sparsify(d);
}

// Positions at least `spacing` voxel apart, `margin` from the faces.
std::vector<Vec3d> separated_positions(const VoxelGrid& g, int count, double spacing, double margin, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(margin, g.nx - 1 - margin), uy(margin, g.ny - 1 - margin),
      uz(margin, g.nz - 1 - margin);
  std::vector<Vec3d> out;
  while (static_cast<int>(out.size()) < count) {
    const Vec3d p{ux(rng), uy(rng), uz(rng)};
    bool free = true;
    for (const Vec3d& q : out) free = free && (p - q).norm() >= spacing;
    if (free) out.push_back(p);
  }
  return out;
}

const Particle* nearest(const std::vector<Particle>& ps, const Vec3d& v) {
  const Particle* best = nullptr;
  for (const Particle& p : ps)
    if (!best || (p.voxel - v).norm() < (best->voxel - v).norm()) best = &p;
  return best;
}

TEST(ParticleExtraction, SubVoxelCentroidOfAGaussianBlobWithinTwoHundredthsOfAVoxel) {
  const VoxelGrid g = grid(48, 40, 32);
  const std::vector<Vec3d> truth = separated_positions(g, 60, 7.0, 4.0, 5);
  const auto report = extract_particles(blobs(g, truth));
  ASSERT_EQ(report.particles.size(), truth.size());
  for (const Vec3d& t : truth) {
    const Particle* p = nearest(report.particles, t);
    ASSERT_NE(p, nullptr);
    EXPECT_LT(std::abs(p->voxel.x - t.x), 0.02) << t.x << " " << t.y << " " << t.z;
    EXPECT_LT(std::abs(p->voxel.y - t.y), 0.02);
    EXPECT_LT(std::abs(p->voxel.z - t.z), 0.02);
    const Vec3d w = g.centre_of(t.x, t.y, t.z);
    EXPECT_LT((p->world - w).norm(), 0.02 * g.voxel_size * std::sqrt(3.0));
  }
}

TEST(ParticleExtraction, BlobSizeExtentsAndIntensityOfAnIsolatedBlob) {
  const VoxelGrid g = grid(24, 24, 24);
  const Vec3d t{11.3, 12.0, 10.6};
  const SparseVolume v = blobs(g, {t}, 3.0);
  const auto report = extract_particles(v);
  ASSERT_EQ(report.particles.size(), 1u);
  const Particle& p = report.particles[0];
  // The truth volume's 3.5-sigma box: voxels with |c - t| <= 2.625 on each axis.
  EXPECT_EQ(p.min_i, 9);   // ceil(11.3 - 2.625)
  EXPECT_EQ(p.max_i, 13);  // floor(11.3 + 2.625)
  EXPECT_EQ(p.min_j, 10);
  EXPECT_EQ(p.max_j, 14);
  EXPECT_EQ(p.min_k, 8);
  EXPECT_EQ(p.max_k, 13);
  EXPECT_EQ(p.voxel_count, 5 * 5 * 6);
  double sum = 0.0;
  float peak = 0.0f;
  for (float x : v.intensity) sum += x, peak = std::max(peak, x);
  EXPECT_NEAR(p.integrated, sum, 1e-6 * sum);
  EXPECT_EQ(p.peak, peak);
  EXPECT_EQ(p.peak_index, g.linear(11, 12, 11));
  EXPECT_NEAR(p.mean_intensity(), sum / 150.0, 1e-9);
}

TEST(ParticleExtraction, TouchingParticlesSplitAlongTheValley) {
  const VoxelGrid g = grid(32, 32, 32);
  // 2.5 voxel apart (3.3 sigma): one connected component above any sensible floor, two peaks.
  const std::vector<Vec3d> pairs[] = {
      {{14.2, 15.0, 15.5}, {16.7, 15.0, 15.5}},  // along x
      {{15.0, 14.1, 15.0}, {15.3, 16.6, 15.4}},  // along y, offset
      {{15.5, 15.5, 14.0}, {15.5, 15.5, 16.5}},  // along z
  };
  for (const auto& pair : pairs) {
    const auto report = extract_particles(blobs(g, pair));
    ASSERT_EQ(report.particles.size(), 2u);
    for (const Vec3d& t : pair) {
      const Particle* p = nearest(report.particles, t);
      // Each basin holds a bit of the other blob's tail (and loses a bit of its own), which
      // pulls the centroids ~0.1 voxel towards each other at 3.3 sigma: bounded at 0.15.
      EXPECT_LT((p->voxel - t).norm(), 0.15) << t.x << " " << t.y << " " << t.z;
    }
  }
}

TEST(ParticleExtraction, PeakThresholdsDropWeakBlobs) {
  const VoxelGrid g = grid(32, 32, 32);
  const SparseVolume v = add(blobs(g, {{8, 8, 8}, {20, 20, 20}}, 1.0), blobs(g, {{8, 22, 14}}, 0.005));
  EXPECT_EQ(extract_particles(v).particles.size(), 2u);  // default: 1 % of the brightest voxel
  ExtractionOptions all;
  all.relative_peak_threshold = 0.0;
  EXPECT_EQ(extract_particles(v, all).particles.size(), 3u);
  ExtractionOptions absolute = all;
  absolute.peak_threshold = 0.5f;
  EXPECT_EQ(extract_particles(v, absolute).particles.size(), 2u);
}

TEST(ParticleExtraction, MaxRadiusLimitsTheBlob) {
  const VoxelGrid g = grid(24, 24, 24);
  ExtractionOptions opt;
  opt.max_radius_voxel = 1;
  const auto report = extract_particles(blobs(g, {{12, 12, 12}}), opt);
  ASSERT_EQ(report.particles.size(), 1u);
  EXPECT_EQ(report.particles[0].voxel_count, 27);
  EXPECT_NEAR(report.particles[0].voxel.x, 12.0, 1e-9);
}

TEST(ParticleExtraction, DenseAndSparseInputAndThreadCountsAgree) {
  const VoxelGrid g = grid(40, 40, 24);
  const std::vector<Vec3d> truth = separated_positions(g, 120, 2.0, 1.0, 9);  // crowded: many touching
  const SparseVolume s = blobs(g, truth);
  ExtractionOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const auto a = extract_particles(s, one);
  const auto b = extract_particles(s, two);
  const auto c = extract_particles(s.to_dense(), two);
  ASSERT_EQ(a.particles.size(), b.particles.size());
  ASSERT_EQ(a.particles.size(), c.particles.size());
  for (std::size_t n = 0; n < a.particles.size(); ++n) {
    EXPECT_EQ(a.particles[n].peak_index, b.particles[n].peak_index);
    EXPECT_EQ(a.particles[n].voxel.x, b.particles[n].voxel.x);
    EXPECT_EQ(a.particles[n].voxel.z, c.particles[n].voxel.z);
    EXPECT_EQ(a.particles[n].voxel_count, c.particles[n].voxel_count);
  }
  EXPECT_EQ(a.active_voxels, s.size());
}

TEST(ParticleExtraction, VoxelFloorAndNaNsAreBackground) {
  const VoxelGrid g = grid(24, 24, 24);
  DenseVolume d = blobs(g, {{12, 12, 12}}).to_dense();
  d.at(3, 3, 3) = NAN;
  d.at(20, 20, 20) = 0.05f;  // a lone voxel below the floor
  ExtractionOptions opt;
  opt.voxel_floor = 0.1f;
  opt.relative_peak_threshold = 0.0;
  const auto report = extract_particles(d, opt);
  ASSERT_EQ(report.particles.size(), 1u);
  // Voxels above 0.1 of a unit-peak blob centred on a voxel: exp(-r2 / 1.125) > 0.1 -> r2 <= 2.
  EXPECT_EQ(report.particles[0].voxel_count, 1 + 6 + 12);
}

TEST(ParticleExtraction, RejectsMalformedVolumesAndOptions) {
  const VoxelGrid g = grid(8, 8, 8);
  SparseVolume v;
  v.grid = g;
  v.index = {5, 3};
  v.intensity = {1.0f, 2.0f};
  EXPECT_THROW(extract_particles(v), tomorig::Error);  // not ascending
  v.index = {3, 600};
  EXPECT_THROW(extract_particles(v), tomorig::Error);  // outside the 512-voxel grid
  v.index = {3};
  EXPECT_THROW(extract_particles(v), tomorig::Error);  // size mismatch
  ExtractionOptions bad;
  bad.max_radius_voxel = 0;
  try {
    extract_particles(SparseVolume{g, {}, {}}, bad);
    FAIL() << "max_radius_voxel 0 accepted";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("max_radius_voxel"), std::string::npos);
  }
  EXPECT_TRUE(extract_particles(SparseVolume{g, {}, {}}).particles.empty());
}

}  // namespace
