// Accuracy of the correlator on volume pairs of known displacement (uniform shifts and the
// Taylor-Green field of thesis Eq. 3.13), and its handling of empty, noisy, edge and masked
// regions. The reference is always the analytic displacement at each node centre.
#include <cmath>
#include <cstdio>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/correlation/correlate.h"
#include "tomorig/simulators/taylor_green.h"
#include "volume_pair.h"

namespace {

using namespace tomorig;
using namespace tomorig::piv;
using corr_test::make_pair;
using corr_test::test_grid;

CorrelationOptions one_pass(WindowSize w, double overlap = 0.5) {
  CorrelationOptions o;
  CorrelationPass p;
  p.window = w;
  p.overlap = overlap;
  o.passes.push_back(p);
  return o;
}

struct Rms {
  double x = 0, y = 0, z = 0, magnitude = 0;
  std::size_t nodes = 0;
};

// RMS error against `truth` (voxels at a voxel position) over interior nodes (the outermost
// layer excluded, as in the tpiv-thesis metric); non-valid nodes count as failures.
Rms rms_error(const VectorField& f, const VoxelGrid& grid, const std::function<Vec3d(const Vec3d&)>& truth,
              std::size_t* not_valid = nullptr) {
  Rms r;
  for (int k = 1; k + 1 < f.nz; ++k)
    for (int j = 1; j + 1 < f.ny; ++j)
      for (int i = 1; i + 1 < f.nx; ++i) {
        const std::size_t n = f.linear(i, j, k);
        if (f.status[n] != VectorStatus::valid && not_valid) ++*not_valid;
        const Vec3d voxel = grid.voxel_of({f.origin.x + i * f.spacing.x, f.origin.y + j * f.spacing.y, f.origin.z + k * f.spacing.z});
        const Vec3d t = truth(voxel);
        const double ex = f.displacement[n].x - t.x, ey = f.displacement[n].y - t.y, ez = f.displacement[n].z - t.z;
        r.x += ex * ex;
        r.y += ey * ey;
        r.z += ez * ez;
        ++r.nodes;
      }
  const double m = r.nodes ? 1.0 / r.nodes : 0.0;
  r.magnitude = std::sqrt((r.x + r.y + r.z) * m);
  r.x = std::sqrt(r.x * m);
  r.y = std::sqrt(r.y * m);
  r.z = std::sqrt(r.z * m);
  return r;
}

void print(const char* what, const Rms& r) {
  std::printf("[ figures  ] %s: RMS x %.4f y %.4f z %.4f magnitude %.4f voxel over %zu nodes\n", what, r.x, r.y, r.z,
              r.magnitude, r.nodes);
}

TEST(Correlate, UniformIntegerShift) {
  const VoxelGrid grid = test_grid(96, 96, 48);
  const Vec3d shift{3, -2, 1};
  auto truth = [&](const Vec3d&) { return shift; };
  const auto pair = make_pair(grid, 0.002, truth);
  // A first pass gives the predictor; the second offsets the windows by it, so that both
  // windows cut the same particles at their faces.
  CorrelationOptions options = one_pass({32, 32, 16});
  options.passes.push_back(options.passes.back());
  CorrelationReport report;
  const VectorField f = correlate(pair.a, pair.b, options, report);
  EXPECT_EQ(f.nx, 5);
  EXPECT_EQ(f.nz, 5);
  std::size_t not_valid = 0;
  const Rms r = rms_error(f, grid, truth, &not_valid);
  print("uniform (3, -2, 1), 32x32x16, 2 passes (integer offset)", r);
  EXPECT_LT(r.magnitude, 0.05);
  EXPECT_EQ(not_valid, 0u);
}

TEST(Correlate, UniformSubVoxelShiftSparseInput) {
  const VoxelGrid grid = test_grid(96, 96, 48);
  const Vec3d shift{0.3, -0.45, 0.2};
  auto truth = [&](const Vec3d&) { return shift; };
  const auto pair = make_pair(grid, 0.002, truth, 11);
  // The same pair through the sparse overload.
  SparseVolume sa, sb;
  sa.grid = sb.grid = grid;
  for (std::size_t n = 0; n < pair.a.values.size(); ++n) {
    if (pair.a.values[n] != 0) sa.index.push_back(std::uint32_t(n)), sa.intensity.push_back(pair.a.values[n]);
    if (pair.b.values[n] != 0) sb.index.push_back(std::uint32_t(n)), sb.intensity.push_back(pair.b.values[n]);
  }
  // One pass, then one deformation pass: both volumes shifted by -/+ half the predictor.
  CorrelationOptions options = one_pass({24, 24, 24});
  options.passes.push_back(options.passes.back());
  options.passes.back().deformation = true;
  CorrelationReport report;
  const VectorField f = correlate(sa, sb, options, report);
  const Rms r = rms_error(f, grid, truth);
  print("uniform (0.3, -0.45, 0.2), 24^3, 1 pass + 1 deformation pass", r);
  EXPECT_LT(r.magnitude, 0.05);
  EXPECT_GT(report.valid_fraction(), 0.95);
}

// Ghost-like noise: volumes a and b each get as many extra blobs again at independent random
// positions (uncorrelated between the exposures). On a uniform shift there is no gradient for
// narrow weights to resolve, so the wider Gaussian, which weighs more of each window's
// particles, must give the smaller error; and a malformed width is refused by name.
TEST(Correlate, WiderGaussianWeightingAveragesMoreParticlesAgainstNoise) {
  const VoxelGrid grid = test_grid(96, 96, 48);
  const Vec3d shift{0.4, -0.3, 0.25};
  auto truth = [&](const Vec3d&) { return shift; };
  auto pair = make_pair(grid, 0.002, truth, 5);
  const auto noise_a = make_pair(grid, 0.002, truth, 101), noise_b = make_pair(grid, 0.002, truth, 202);
  for (std::size_t n = 0; n < pair.a.values.size(); ++n) {
    pair.a.values[n] += noise_a.a.values[n];
    pair.b.values[n] += noise_b.b.values[n];
  }
  auto run = [&](double sigma) {
    CorrelationOptions options = CorrelationOptions::multigrid({24, 24, 24}, 0.5, 1);
    options.weighting = WindowWeighting::gaussian;
    options.gaussian_sigma = sigma;
    CorrelationReport report;
    return rms_error(correlate(pair.a, pair.b, options, report), grid, truth);
  };
  const Rms narrow = run(0.25), wide = run(0.5);
  print("uniform shift + uncorrelated blobs, Gaussian sigma W/4", narrow);
  print("uniform shift + uncorrelated blobs, Gaussian sigma W/2", wide);
  EXPECT_LT(wide.magnitude, 0.8 * narrow.magnitude);
  CorrelationOptions bad = CorrelationOptions::multigrid({24, 24, 24}, 0.5, 1);
  bad.gaussian_sigma = 0.0;
  CorrelationReport report;
  try {
    correlate(pair.a, pair.b, bad, report);
    ADD_FAILURE() << "gaussian_sigma 0 was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("gaussian_sigma"), std::string::npos) << e.what();
  }
}

TEST(Correlate, LargeSubVoxelShiftWithMultigridAndDeformation) {
  const VoxelGrid grid = test_grid(96, 96, 48);
  const Vec3d shift{6.4, -3.7, 2.3};
  auto truth = [&](const Vec3d&) { return shift; };
  const auto pair = make_pair(grid, 0.002, truth, 5);
  for (Interpolation interpolation : {Interpolation::trilinear, Interpolation::cubic_bspline}) {
    CorrelationReport report;
    const VectorField f = correlate(pair.a, pair.b, CorrelationOptions::multigrid({16, 16, 16}, 0.5, 2, interpolation), report);
    const Rms r = rms_error(f, grid, truth);
    print(interpolation == Interpolation::trilinear ? "uniform (6.4, -3.7, 2.3), multigrid + 2 deformation, trilinear"
                                                    : "uniform (6.4, -3.7, 2.3), multigrid + 2 deformation, B-spline",
          r);
    // Trilinear interpolation low-passes the particle images differently at different
    // fractional shifts, which leaves ~0.1 voxel; the cubic B-spline does not (Sect. 5.4.3).
    EXPECT_LT(r.magnitude, interpolation == Interpolation::trilinear ? 0.12 : 0.05);
    EXPECT_EQ(report.passes.size(), 4u);
  }
}

// Eq. 3.13 with A = 5 voxel and the period scaled from 256 to 128 voxel for the reduced grid;
// windows of 16^3 hold about 10 particles, as in the tpiv-thesis case.
TEST(Correlate, TaylorGreenDeformationBeatsIntegerOffset) {
  const VoxelGrid grid = test_grid(96, 96, 48);
  const sim::TaylorGreenFlow flow(grid, 5.0, 128.0);
  auto truth = [&](const Vec3d& v) { return flow.displacement_voxel(v); };
  const auto pair = make_pair(grid, 10.0 / (16 * 16 * 16), truth, 21);

  CorrelationOptions without = CorrelationOptions::multigrid({16, 16, 16}, 0.75, 0);
  without.passes.push_back(without.passes.back());  // same pass count, integer offset only
  without.passes.push_back(without.passes.back());
  without.weighting = WindowWeighting::gaussian;
  CorrelationOptions with = CorrelationOptions::multigrid({16, 16, 16}, 0.75, 2);
  with.weighting = WindowWeighting::gaussian;
  CorrelationOptions top_hat = with;
  top_hat.weighting = WindowWeighting::top_hat;

  CorrelationReport report_without, report_with, report_top_hat;
  const Rms r_without = rms_error(correlate(pair.a, pair.b, without, report_without), grid, truth);
  const Rms r_top_hat = rms_error(correlate(pair.a, pair.b, top_hat, report_top_hat), grid, truth);
  const VectorField f = correlate(pair.a, pair.b, with, report_with);
  std::size_t not_valid = 0;
  const Rms r_with = rms_error(f, grid, truth, &not_valid);
  print("Taylor-Green A=5 p=128, 16^3 75 %, Gaussian window, no deformation", r_without);
  print("Taylor-Green A=5 p=128, 16^3 75 %, top-hat window, 2 deformation passes (B-spline)", r_top_hat);
  print("Taylor-Green A=5 p=128, 16^3 75 %, Gaussian window, 2 deformation passes (B-spline)", r_with);
  std::printf("[ figures  ] valid fraction %.3f, correlation %.3f s\n", report_with.valid_fraction(), report_with.seconds_total);
  EXPECT_LT(r_with.magnitude, 0.18);
  EXPECT_LT(r_top_hat.magnitude, 0.25);
  EXPECT_LT(r_with.magnitude, 0.5 * r_without.magnitude);
  EXPECT_LT(double(not_valid), 0.1 * r_with.nodes);
}

TEST(Correlate, ShiftAtTheEdgeOfTheCorrelationPlaneUsesTheFallback) {
  // A shift of -8 voxel in x in 16-voxel windows puts the peak on the plane's lowest lag.
  const VoxelGrid grid = test_grid(64, 48, 48);
  auto truth = [](const Vec3d&) { return Vec3d{-8, 0, 0}; };
  const auto pair = make_pair(grid, 0.004, truth, 9);
  CorrelationOptions options = one_pass({16, 16, 16});
  options.median_test.enabled = false;
  CorrelationReport report;
  const VectorField f = correlate(pair.a, pair.b, options, report);
  EXPECT_GE(report.passes[0].peak_fallbacks, f.count() / 2);
  std::size_t at_edge = 0;
  for (std::size_t n = 0; n < f.count(); ++n) at_edge += std::fabs(f.displacement[n].x + 8.0f) < 0.6f;
  EXPECT_GE(at_edge, f.count() / 2);
}

TEST(Correlate, UncorrelatedRegionIsInvalidByPeakThreshold) {
  // Particles for x < 48, independent white noise in each volume for x >= 48.
  const VoxelGrid grid = test_grid(96, 64, 32);
  auto truth = [](const Vec3d&) { return Vec3d{1.5, 0.5, -0.5}; };
  auto pair = make_pair(grid, 0.003, truth, 4);
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> noise(0.0f, 1.0f);
  for (int k = 0; k < grid.nz; ++k)
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 48; i < grid.nx; ++i) {
        pair.a.at(i, j, k) = noise(rng);
        pair.b.at(i, j, k) = noise(rng);
      }
  for (int k = 0; k < grid.nz; ++k)
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 44; i < 48; ++i) pair.a.at(i, j, k) = pair.b.at(i, j, k) = 0.0f;  // a clean border
  CorrelationOptions options = one_pass({16, 16, 16});
  CorrelationReport report;
  const VectorField f = correlate(pair.a, pair.b, options, report);
  std::size_t noise_nodes = 0, particle_nodes = 0;
  for (int k = 0; k < f.nz; ++k)
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i) {
        const std::size_t n = f.linear(i, j, k);
        const int first_voxel = i * 8;
        if (first_voxel >= 48) {
          ++noise_nodes;
          EXPECT_EQ(f.status[n], VectorStatus::invalid) << "node " << i << " peak " << f.peak[n];
          EXPECT_LT(f.peak[n], 0.1f);
        } else if (first_voxel + 16 <= 44) {
          ++particle_nodes;
          EXPECT_EQ(f.status[n], VectorStatus::valid) << "node " << i;
          EXPECT_GT(f.peak[n], 0.5f);
        }
      }
  EXPECT_GT(noise_nodes, 0u);
  EXPECT_GT(particle_nodes, 0u);
  EXPECT_GE(report.passes[0].low_peak, noise_nodes);
}

TEST(Correlate, EmptyWindowsAreInvalid) {
  const VoxelGrid grid = test_grid(48, 48, 32);
  const DenseVolume empty(grid);
  CorrelationReport report;
  const VectorField f = correlate(empty, empty, one_pass({16, 16, 16}), report);
  for (std::size_t n = 0; n < f.count(); ++n) {
    EXPECT_EQ(f.status[n], VectorStatus::invalid);
    EXPECT_EQ(f.peak[n], 0.0f);
  }
  EXPECT_EQ(report.valid_fraction(), 0.0);
}

TEST(Correlate, IlluminationMaskFlagsDimNodes) {
  const VoxelGrid grid = test_grid(64, 64, 48);
  auto truth = [](const Vec3d&) { return Vec3d{1, 1, 1}; };
  const auto pair = make_pair(grid, 0.002, truth, 2);
  CorrelationOptions options = one_pass({16, 16, 16});
  // A light sheet bright for world z < 0 only (the grid is centred on z = 0).
  options.illumination = [](const Vec3d& world) { return world.z < -1e-6 ? 0.9 : 0.2; };
  CorrelationReport report;
  const VectorField f = correlate(pair.a, pair.b, options, report);
  std::size_t dim = 0;
  for (int k = 0; k < f.nz; ++k)
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i) {
        const double z = f.origin.z + k * f.spacing.z;
        const VectorStatus s = f.status[f.linear(i, j, k)];
        if (z >= -1e-6) {
          ++dim;
          EXPECT_EQ(s, VectorStatus::invalid);
        } else {
          EXPECT_EQ(s, VectorStatus::valid);
        }
      }
  EXPECT_GT(dim, 0u);
  EXPECT_EQ(report.passes[0].masked, dim);
}

TEST(Correlate, FieldGeometryIsInWorldMillimetres) {
  const VoxelGrid grid = test_grid(64, 48, 32);
  const auto pair = make_pair(grid, 0.002, [](const Vec3d&) { return Vec3d{}; });
  CorrelationReport report;
  const VectorField f = correlate(pair.a, pair.b, one_pass({16, 16, 16}, 0.75), report);
  // Windows of 16 at a step of 4: nodes at voxel 7.5, 11.5, ...; (64 - 16) / 4 + 1 = 13 along x.
  EXPECT_EQ(f.nx, 13);
  EXPECT_EQ(f.ny, 9);
  EXPECT_EQ(f.nz, 5);
  EXPECT_NEAR(f.origin.x, grid.centre_of(7.5, 7.5, 7.5).x, 1e-9);
  EXPECT_NEAR(f.spacing.x, 4 * grid.voxel_size, 1e-12);
}

}  // namespace

// The sparse direct correlation of the deformation passes evaluates Eq. 2.16 at lags -1..1 with
// the FFT path's weights, means, energies and circular indexing: on the Taylor-Green pair (with
// Gaussian and top-hat weights) it must give the FFT's vectors to well below their error, and be
// as accurate against the analytic flow. (These volumes, ~10 particles per 16^3 window, are
// 13 % occupied: the automatic choice of a deformation pass correlates directly up to a
// quarter, where the direct pass still costs less than the FFT.)
// Correlates the Taylor-Green pair with `window` final windows at 75 % overlap twice, the
// deformation passes forced to FFT and to direct, and checks that the direct passes give the
// FFT's vectors (up to the dropped near-zero voxels and rounding) and its accuracy.
void expect_direct_matches_fft(WindowSize window, WindowWeighting weighting, const char* label) {
  const VoxelGrid grid = test_grid(96, 96, 48);
  const sim::TaylorGreenFlow flow(grid, 5.0, 128.0);
  auto truth = [&](const Vec3d& v) { return flow.displacement_voxel(v); };
  const auto pair = make_pair(grid, 10.0 / (16 * 16 * 16), truth, 21);
  CorrelationOptions fft = CorrelationOptions::multigrid(window, 0.75, 2);
  fft.weighting = weighting;
  for (CorrelationPass& p : fft.passes) p.method = CorrelationMethod::fft;
  CorrelationOptions direct = fft, automatic = fft;
  for (CorrelationPass& p : direct.passes) p.method = CorrelationMethod::direct;
  for (CorrelationPass& p : automatic.passes) p.method = CorrelationMethod::automatic;
  // The integer-offset pass stays FFT here, so both runs feed the deformation passes the same
  // predictor (DirectPassesWithoutDeformationFindTheFftPeak tests that pass's direct search).
  direct.passes[1].method = CorrelationMethod::fft;
  CorrelationReport report_fft, report_direct, report_automatic;
  const VectorField f_fft = correlate(pair.a, pair.b, fft, report_fft);
  const VectorField f_direct = correlate(pair.a, pair.b, direct, report_direct);
  correlate(pair.a, pair.b, automatic, report_automatic);
  ASSERT_EQ(report_direct.passes.size(), 4u);
  for (std::size_t p = 2; p < 4; ++p) {
    EXPECT_STREQ(report_direct.passes[p].method, "direct");
    EXPECT_STREQ(report_fft.passes[p].method, "fft");
    EXPECT_LT(report_direct.passes[p].fft_fallbacks, f_direct.count() / 20);
  }
  double differences = 0, largest = 0;
  std::size_t compared = 0, same_status = 0;
  for (std::size_t n = 0; n < f_fft.count(); ++n) {
    same_status += f_fft.status[n] == f_direct.status[n];
    if (f_fft.status[n] != VectorStatus::valid || f_direct.status[n] != VectorStatus::valid) continue;
    const double dx = f_fft.displacement[n].x - f_direct.displacement[n].x,
                 dy = f_fft.displacement[n].y - f_direct.displacement[n].y,
                 dz = f_fft.displacement[n].z - f_direct.displacement[n].z;
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    differences += d * d;
    largest = std::max(largest, d);
    ++compared;
  }
  const double rms_difference = std::sqrt(differences / std::max<std::size_t>(compared, 1));
  const Rms r_fft = rms_error(f_fft, grid, truth), r_direct = rms_error(f_direct, grid, truth);
  std::printf("[ figures  ] %s: direct vs FFT RMS difference %.5f (largest %.4f) voxel over %zu vectors; "
              "RMS error FFT %.4f, direct %.4f; FFT fallbacks %zu + %zu; occupancy %.3f, choice %s\n",
              label, rms_difference, largest, compared, r_fft.magnitude, r_direct.magnitude,
              report_direct.passes[2].fft_fallbacks, report_direct.passes[3].fft_fallbacks,
              report_automatic.passes[3].occupied_fraction, report_automatic.passes[3].method);
  EXPECT_STREQ(report_automatic.passes[3].method, report_automatic.passes[3].occupied_fraction <= 0.25 ? "direct" : "fft");
  EXPECT_GT(compared, f_fft.count() * 9 / 10);
  EXPECT_GT(same_status, f_fft.count() * 98 / 100);
  // The voxels below kOccupiedThreshold (0.3 % of the largest) are left out of the direct sums:
  // with top-hat windows, where a faint voxel at a window's edge weighs as much as one at its
  // centre, that moved the vectors by 0.0115 voxel rms (0.0070 at a threshold of 0.1 %), while
  // the error against the flow stayed within 0.0004 voxel of the FFT's.
  EXPECT_LT(rms_difference, 0.015);
  EXPECT_LT(r_direct.magnitude, r_fft.magnitude + 0.005);
}

// The passes without deformation correlate directly at the 27 lags around the peak of their
// windows binned 2x (the binned pre-search), falling back to the FFT where the peak lies beyond.
// Against the FFT on the same windows: the integer-offset pass (after the binned pass, on a
// Taylor-Green pair whose gradients split the peaks of 16^3 windows) and a single pass: the
// same vectors in nearly every window where both are valid, and as accurate against the
// analytic flow (the few windows where the binned peak leads elsewhere are a different, not a
// worse, choice between split peaks). The offset windows that reach past the volume's faces read
// zeros there as the FFT's do.
TEST(Correlate, DirectPassesWithoutDeformationFindTheFftPeak) {
  const VoxelGrid grid = test_grid(96, 96, 48);
  struct Case {
    const char* label;
    double amplitude, period;
    CorrelationOptions options;
  };
  CorrelationOptions offset_pass = CorrelationOptions::multigrid({16, 16, 16}, 0.5, 0);
  std::vector<Case> cases = {{"integer-offset pass, strong shear", 5.0, 128.0, offset_pass},
                             {"single pass", 2.0, 256.0, one_pass({16, 16, 16})}};
  for (Case& c : cases) {
    const sim::TaylorGreenFlow flow(grid, c.amplitude, c.period);
    auto truth = [&](const Vec3d& v) { return flow.displacement_voxel(v); };
    const auto pair = make_pair(grid, 0.002, truth, 33);
    for (WindowWeighting weighting : {WindowWeighting::gaussian, WindowWeighting::top_hat}) {
      CorrelationOptions fft = c.options;
      fft.weighting = weighting;
      fft.passes.back().method = CorrelationMethod::fft;
      CorrelationOptions direct = fft;
      direct.passes.back().method = CorrelationMethod::direct;
      CorrelationReport report_fft, report_direct;
      const VectorField f_fft = correlate(pair.a, pair.b, fft, report_fft);
      const VectorField f_direct = correlate(pair.a, pair.b, direct, report_direct);
      EXPECT_STREQ(report_direct.passes.back().method, "direct");
      EXPECT_STREQ(report_fft.passes.back().method, "fft");
      EXPECT_LT(report_direct.passes.back().fft_fallbacks, f_direct.count() / 10);
      std::size_t both_valid = 0, same = 0, valid_fft = 0, valid_direct = 0;
      for (std::size_t n = 0; n < f_fft.count(); ++n) {
        valid_fft += f_fft.status[n] == VectorStatus::valid;
        valid_direct += f_direct.status[n] == VectorStatus::valid;
        if (f_fft.status[n] != VectorStatus::valid || f_direct.status[n] != VectorStatus::valid) continue;
        ++both_valid;
        const double dx = f_fft.displacement[n].x - f_direct.displacement[n].x,
                     dy = f_fft.displacement[n].y - f_direct.displacement[n].y,
                     dz = f_fft.displacement[n].z - f_direct.displacement[n].z;
        same += std::sqrt(dx * dx + dy * dy + dz * dz) < 0.01;
      }
      const Rms r_fft = rms_error(f_fft, grid, truth), r_direct = rms_error(f_direct, grid, truth);
      std::printf("[ figures  ] %s, %s: %zu of %zu vectors valid in both the same within 0.01 voxel; valid FFT %zu, "
                  "direct %zu of %zu; RMS error FFT %.4f, direct %.4f; FFT fallbacks %zu; occupancy %.3f\n",
                  c.label, weighting == WindowWeighting::gaussian ? "Gaussian" : "top hat", same, both_valid,
                  valid_fft, valid_direct, f_fft.count(), r_fft.magnitude, r_direct.magnitude,
                  report_direct.passes.back().fft_fallbacks, report_direct.passes.back().occupied_fraction);
      EXPECT_GT(both_valid, f_fft.count() / 2);
      EXPECT_GE(same, both_valid * 95 / 100);
      EXPECT_GE(valid_direct, valid_fft * 95 / 100);
      EXPECT_LT(r_direct.magnitude, r_fft.magnitude + 0.01);
    }
  }
}

// 16^3 windows at 75 %: step 4, so every window starts and ends on the borders of the 4^3
// blocks of the occupied-voxel lists, and its wrapped lags come from the blocks' face lists.
TEST(Correlate, DirectDeformationPassesMatchTheFftPasses) {
  expect_direct_matches_fft({16, 16, 16}, WindowWeighting::gaussian, "Gaussian");
  expect_direct_matches_fft({16, 16, 16}, WindowWeighting::top_hat, "top hat");
}

// 18^3 windows at 75 %: step 5 does not divide 18, so the windows end inside a block and the
// wrapped lags come from the walk over every block touching the shell (the other path).
TEST(Correlate, DirectPassesOffTheBlockBordersMatchTheFftPasses) {
  expect_direct_matches_fft({18, 18, 18}, WindowWeighting::gaussian, "Gaussian, 18^3 windows off the block borders");
}

// Nodes where two fields of the same geometry differ at all (status or any displacement bit).
std::size_t nodes_differing(const VectorField& a, const VectorField& b) {
  std::size_t differing = 0;
  for (std::size_t n = 0; n < a.count(); ++n)
    differing += a.status[n] != b.status[n] || a.displacement[n].x != b.displacement[n].x ||
                 a.displacement[n].y != b.displacement[n].y || a.displacement[n].z != b.displacement[n].z;
  return differing;
}

// The volume buffers (coefficients, deformed pair, masks, occupied lists) are kept by the
// calling thread from one correlation to the next: a correlation after another of a different
// pair (other volumes, other grid, other binning) must give exactly what the same correlation
// gives on a thread that never correlated before.
TEST(Correlate, KeptBuffersCarryNothingIntoTheNextCorrelation) {
  const VoxelGrid grid = test_grid(64, 64, 32);
  const sim::TaylorGreenFlow flow(grid, 5.0, 128.0);
  const auto pair = make_pair(grid, 10.0 / (16 * 16 * 16), [&](const Vec3d& v) { return flow.displacement_voxel(v); }, 5);
  const VoxelGrid other_grid = test_grid(48, 48, 32);
  const auto other = make_pair(other_grid, 0.004, [](const Vec3d&) { return Vec3d{1.3, -0.6, 0.4}; }, 9);
  CorrelationOptions options = CorrelationOptions::multigrid({16, 16, 16}, 0.75, 2);
  options.weighting = WindowWeighting::gaussian;
  options.gaussian_sigma = 0.5;
  options.passes.back().method = CorrelationMethod::direct;  // the occupied lists are reused too

  VectorField fresh;
  std::thread([&] {
    CorrelationReport report;
    fresh = correlate(pair.a, pair.b, options, report);
  }).join();
  CorrelationReport report;
  (void)correlate(other.a, other.b, CorrelationOptions::multigrid({16, 16, 16}, 0.5, 1), report);
  (void)correlate(pair.b, pair.a, options, report);  // same grid, the volumes swapped
  const VectorField again = correlate(pair.a, pair.b, options, report);
  ASSERT_EQ(again.count(), fresh.count());
  EXPECT_EQ(nodes_differing(again, fresh), 0u);
  EXPECT_STREQ(report.passes.back().method, "direct");
}

namespace {

tomorig::SparseVolume sparse_of(const tomorig::DenseVolume& d) {
  tomorig::SparseVolume s;
  s.grid = d.grid;
  for (std::size_t n = 0; n < d.values.size(); ++n)
    if (d.values[n] != 0.0f) {
      s.index.push_back(static_cast<std::uint32_t>(n));
      s.intensity.push_back(d.values[n]);
    }
  return s;
}

}  // namespace

// Sparse volumes (as the back-end's reconstructions give them) are densified into buffers the
// correlating thread keeps: after another pair on a larger grid, a sparse pair must correlate
// exactly as its dense form does.
TEST(Correlate, SparseVolumesCorrelateAsTheirDenseFormAfterAnotherPair) {
  using namespace tomorig;
  using namespace tomorig::piv;
  const VoxelGrid grid = corr_test::test_grid(64, 64, 32);
  const auto pair = corr_test::make_pair(grid, 0.003, [](const Vec3d&) { return Vec3d{1.4, -0.7, 0.3}; }, 7);
  const VoxelGrid other_grid = corr_test::test_grid(80, 64, 48);
  const auto other = corr_test::make_pair(other_grid, 0.003, [](const Vec3d&) { return Vec3d{-2.0, 0.5, 1.0}; }, 8);
  const CorrelationOptions options = CorrelationOptions::multigrid({16, 16, 16}, 0.5, 1);
  CorrelationReport report;
  const VectorField dense = correlate(pair.a, pair.b, options, report);
  (void)correlate(sparse_of(other.a), sparse_of(other.b), options, report);
  const VectorField sparse = correlate(sparse_of(pair.a), sparse_of(pair.b), options, report);
  ASSERT_EQ(sparse.count(), dense.count());
  EXPECT_EQ(nodes_differing(sparse, dense), 0u);
}
