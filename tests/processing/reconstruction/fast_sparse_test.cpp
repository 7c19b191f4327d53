// The fast paths of the sparse reconstruction against slow references: the inlined exp, the
// per-voxel lattice positions, MLOS against a brute-force dense pass through the camera model
// (pinhole and a distorting model), pruning, the iteration observer, and the rotated
// elliptical PSF (Eq. 3.8) on particle images rendered here with that ellipse.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "reduced_case.h"
#include "tomorig/core/error.h"
// Private headers of the reconstruction, tested directly.
#include "../../../processing/src/reconstruction/fast_math.h"
#include "../../../processing/src/reconstruction/grid_projector.h"
#include "../../../processing/src/reconstruction/prepared_input.h"
#include "../../../processing/src/reconstruction/weight_table.h"

namespace {

using namespace tomorig;

TEST(FastExp, MatchesStdExpToFloatPrecision) {
  double worst = 0;
  for (float x = -40.0f; x <= 40.0f; x += 0.0137f) {
    const double exact = std::exp(static_cast<double>(x));
    worst = std::max(worst, std::fabs(recon::detail::fast_exp(x) - exact) / exact);
  }
  EXPECT_LT(worst, 4e-6);
  EXPECT_GT(recon::detail::fast_exp(-1000.0f), 0.0f);  // clamped, not 0 or NaN
  EXPECT_TRUE(std::isfinite(recon::detail::fast_exp(1000.0f)));
}

TEST(FastLog, MatchesStdLog) {
  double worst = 0;
  for (float x = 1e-7f; x < 1e4f; x *= 1.0013f)
    worst = std::max(worst, std::fabs(recon::detail::fast_log(x) - std::log(static_cast<double>(x))));
  EXPECT_LT(worst, 3e-6);
  EXPECT_EQ(recon::detail::fast_log(1.0f), 0.0f);
}

// A non-pinhole model: the simulator's camera with a strong wavy distortion, so that the
// lattice is refined or every voxel projected exactly (the general path).
class WavyCamera final : public calibration::CameraModel {
 public:
  explicit WavyCamera(const calibration::CameraModel& base) : base_(base.clone()) {}
  std::string model_name() const override { return "wavy"; }
  Vec2d project(const Vec3d& world) const override {
    const Vec2d p = base_->project(world);
    return {p.x + 0.8 * std::sin(p.y / 2.0), p.y + 0.6 * std::sin(p.x / 1.7)};
  }
  Vec3d back_project(const Vec2d& pixel, double z) const override { return base_->back_project(pixel, z); }
  Ray line_of_sight(const Vec2d& pixel) const override { return base_->line_of_sight(pixel); }
  std::unique_ptr<CameraModel> clone() const override { return std::make_unique<WavyCamera>(*base_); }

 private:
  std::unique_ptr<CameraModel> base_;
};

const recon_test::ReducedCase& mlos_case() {
  static const recon_test::ReducedCase rc = recon_test::make_case(64, 20, 80, 0.04, 11);
  return rc;
}

TEST(GridProjector, PositionsOfListedVoxelsMatchTheWholeRow) {
  const recon_test::ReducedCase& rc = mlos_case();
  const WavyCamera wavy(rc.rig->cameras()[0].model);
  recon::ReconstructionInput input = rc.input();
  input.cameras[1] = &wavy;
  recon::ReconstructionOptions options;
  const recon::detail::PreparedInput in = recon::detail::prepare_input(input, options);
  const recon::detail::GridProjector projector(in);
  EXPECT_GT(projector.step(0), 1);
  EXPECT_LT(projector.step(1), projector.step(0));  // the wavy model needs a finer lattice or exact projection
  const VoxelGrid& g = in.grid;
  std::vector<int> listed;
  for (int i = 0; i < g.nx; i += 3) listed.push_back(i);
  std::vector<float> u(g.nx), v(g.nx), ul(g.nx, -1.0f), vl(g.nx, -1.0f);
  for (std::size_t c = 0; c < 2; ++c)
    for (int k = 0; k < g.nz; k += 5)
      for (int j = 0; j < g.ny; j += 7) {
        projector.row(c, j, k, u.data(), v.data());
        projector.row_at(c, j, k, listed.data(), static_cast<int>(listed.size()), ul.data(), vl.data());
        for (int i : listed) {
          ASSERT_NEAR(ul[i], u[i], 1e-4) << "camera " << c << " voxel " << i << "," << j << "," << k;
          ASSERT_NEAR(vl[i], v[i], 1e-4);
        }
      }
}

// MLOS by brute force: every voxel, every camera, exact projection, bilinear sampling of the
// thresholded normalised image (pixels below 5 % of the maximum are empty).
std::vector<float> brute_force_mlos(const recon::detail::PreparedInput& in, double threshold) {
  const VoxelGrid& g = in.grid;
  std::vector<float> out(g.voxel_count(), 0.0f);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        double product = 1.0;
        for (std::size_t c = 0; c < in.camera_count() && product > 0; ++c) {
          const recon::detail::CameraImage& im = in.images[c];
          const float cut = static_cast<float>(threshold) * im.max;
          auto pixel = [&](int x, int y) -> double {
            if (x < 0 || y < 0 || x >= im.width || y >= im.height) return 0.0;
            const float p = im.at(x, y);
            return p > 0 && p >= cut ? p : 0.0;
          };
          const Vec2d p = in.cameras[c]->project(g.centre_of(i, j, k));
          if (!(p.x >= -0.5 && p.x <= im.width - 0.5 && p.y >= -0.5 && p.y <= im.height - 0.5)) {
            product = 0;
            break;
          }
          const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
          const double ax = p.x - x, ay = p.y - y;
          product *= (1 - ay) * ((1 - ax) * pixel(x, y) + ax * pixel(x + 1, y)) +
                     ay * ((1 - ax) * pixel(x, y + 1) + ax * pixel(x + 1, y + 1));
        }
        out[g.linear(i, j, k)] = static_cast<float>(product);
      }
  return out;
}

void expect_mlos_matches_brute_force(const recon::ReconstructionInput& input) {
  recon::ReconstructionOptions options;
  options.algorithm = "mlos";
  options.mlos_threshold = 0.05;
  recon::ReconstructionReport report;
  const SparseVolume fast = recon::make_reconstructor(options)->reconstruct(input, report);
  const recon::detail::PreparedInput in = recon::detail::prepare_input(input, options);
  const std::vector<float> slow = brute_force_mlos(in, 0.05);
  const std::size_t slow_count = static_cast<std::size_t>(std::count_if(slow.begin(), slow.end(), [](float x) { return x > 0; }));
  ASSERT_GT(slow_count, 1000u);
  // Positions differ from exact projection by < 0.01 px, so only voxels at the very edge of a
  // non-empty neighbourhood may differ.
  std::size_t both = 0;
  double worst = 0, peak = 0;
  for (float x : slow) peak = std::max(peak, static_cast<double>(x));
  for (std::size_t n = 0; n < fast.size(); ++n) {
    const float s = slow[fast.index[n]];
    both += s > 0;
    worst = std::max(worst, std::fabs(static_cast<double>(s) - fast.intensity[n]));
  }
  EXPECT_GT(static_cast<double>(both), 0.995 * static_cast<double>(slow_count));
  EXPECT_GT(static_cast<double>(both), 0.995 * static_cast<double>(fast.size()));
  EXPECT_LT(worst, 0.02 * peak);
}

TEST(Mlos, MatchesBruteForceThroughThePinholeModel) { expect_mlos_matches_brute_force(mlos_case().input()); }

TEST(Mlos, MatchesBruteForceThroughADistortingModel) {
  const recon_test::ReducedCase& rc = mlos_case();
  const WavyCamera wavy(rc.rig->cameras()[2].model);
  recon::ReconstructionInput input = rc.input();
  input.cameras[2] = &wavy;  // its images no longer match the model: fine for an MLOS comparison
  expect_mlos_matches_brute_force(input);
}

const recon_test::ReducedCase& fmart_case() {
  static const recon_test::ReducedCase rc = recon_test::make_case(96, 32, 110, 0.05, 5);
  return rc;
}

TEST(Fmart, PruningDropsFaintVoxelsWithoutLosingQuality) {
  const recon_test::ReducedCase& rc = fmart_case();
  const DenseVolume truth = recon_test::truth_volume(rc.grid, rc.particles);
  recon::ReconstructionOptions o;
  o.algorithm = "fmart";
  o.max_iterations = 6;
  o.prune_fraction = 0.0;
  recon::ReconstructionReport full_report, pruned_report;
  const double q_full = recon_test::quality(recon::make_reconstructor(o)->reconstruct(rc.input(), full_report), truth);
  o.prune_fraction = 1e-3;
  const double q_pruned =
      recon_test::quality(recon::make_reconstructor(o)->reconstruct(rc.input(), pruned_report), truth);
  EXPECT_GT(q_full, 0.8);
  EXPECT_NEAR(q_pruned, q_full, 0.01);
  ASSERT_EQ(pruned_report.history.size(), 6u);
  EXPECT_EQ(full_report.history.back().live_voxels, full_report.active_voxels);
  // Ghost voxels decay by orders of magnitude within a few iterations and leave the list.
  EXPECT_LT(pruned_report.history[2].live_voxels, full_report.active_voxels * 7 / 10);
  EXPECT_LE(pruned_report.history[5].live_voxels, pruned_report.history[2].live_voxels);
}

TEST(Reconstructor, ObserverSeesTheStartAndEveryIteration) {
  const recon_test::ReducedCase& rc = fmart_case();
  const DenseVolume truth = recon_test::truth_volume(rc.grid, rc.particles);
  for (const char* algorithm : {"fmart", "smart"}) {
    recon::ReconstructionOptions o;
    o.algorithm = algorithm;
    o.max_iterations = 4;
    auto r = recon::make_reconstructor(o);
    std::vector<int> seen;
    std::vector<double> elapsed, q;
    r->set_iteration_observer([&](const recon::IterationView& view) {
      seen.push_back(view.iteration);
      elapsed.push_back(view.elapsed_seconds);
      EXPECT_EQ(view.stats == nullptr, view.iteration == 0);
      q.push_back(recon_test::quality(view.volume(), truth));
    });
    recon::ReconstructionReport report;
    const SparseVolume final_volume = r->reconstruct(rc.input(), report);
    EXPECT_EQ(seen, (std::vector<int>{0, 1, 2, 3, 4})) << algorithm;
    EXPECT_TRUE(std::is_sorted(elapsed.begin(), elapsed.end())) << algorithm;
    EXPECT_LE(elapsed.back(), report.seconds + 1e-6) << algorithm;
    EXPECT_GT(report.observer_seconds, 0.0) << algorithm;
    EXPECT_GT(q.back(), q.front() + 0.1) << algorithm << ": iterations improve on MLOS";
    EXPECT_NEAR(q.back(), recon_test::quality(final_volume, truth), 1e-9) << algorithm;
  }
}

TEST(PatchWeights, AxisAlignedEllipseEqualsTheSeparableWeights) {
  const int p = 5, steps = 64;
  recon::PsfSample psf;
  psf.sigma_u_px = 0.9;
  psf.sigma_v_px = 0.6;
  psf.angle_rad = 0.0;
  EXPECT_FALSE(recon::detail::is_rotated(psf));
  const recon::detail::PatchWeights block({psf}, p, steps, 1);
  for (int qv : {0, 17, 40})
    for (int qu : {0, 9, 63}) {
      const float* w = block.table() + static_cast<std::size_t>(block.row(0, qu, qv)) * p * p;
      for (int b = 0; b < p; ++b)
        for (int a = 0; a < p; ++a) {
          const double du = a - static_cast<double>(qu) / steps - 0.5 * (p - 1) + 0.5;
          const double dv = b - static_cast<double>(qv) / steps - 0.5 * (p - 1) + 0.5;
          const double separable = recon::detail::pixel_integrated_gaussian(du, 0.9) *
                                   recon::detail::pixel_integrated_gaussian(dv, 0.6);
          ASSERT_NEAR(w[b * p + a], separable, 2e-3);
        }
    }
}

TEST(PatchWeights, QuarterTurnSwapsTheAxes) {
  recon::PsfSample a, b;
  a.sigma_u_px = 1.1;
  a.sigma_v_px = 0.5;
  a.angle_rad = 0.4;
  b.sigma_u_px = 0.5;
  b.sigma_v_px = 1.1;
  b.angle_rad = 0.4 + std::numbers::pi / 2;
  EXPECT_TRUE(recon::detail::is_rotated(a));
  for (double du : {-1.0, 0.0, 0.7})
    for (double dv : {-0.4, 0.3, 1.2})
      EXPECT_NEAR(recon::detail::pixel_integrated_gaussian_2d(du, dv, a),
                  recon::detail::pixel_integrated_gaussian_2d(du, dv, b), 1e-9);
  // The elongation follows the angle: along the major axis the weight falls off more slowly.
  const double c = std::cos(0.4), s = std::sin(0.4);
  EXPECT_GT(recon::detail::pixel_integrated_gaussian_2d(1.5 * c, 1.5 * s, a),
            5.0 * recon::detail::pixel_integrated_gaussian_2d(-1.5 * s, 1.5 * c, a));
}

TEST(PsfModel, AngleIsInterpolatedAndChecked) {
  recon::PsfModel psf{{{-1.0, 1.0, 0.5, 0.0}, {1.0, 1.0, 0.5, 0.8}}};
  EXPECT_NEAR(psf.at(0.0).angle_rad, 0.4, 1e-12);
  EXPECT_NO_THROW(psf.validate("psf"));
  psf.samples[1].angle_rad = 4.0;
  EXPECT_THROW(psf.validate("psf"), Error);
}

// Particle images of a rotated elliptical Gaussian, rendered here by 6 x 6 sub-samples per
// pixel (independently of the reconstruction's weight tables).
std::vector<Image> render_elliptical(const recon_test::ReducedCase& rc, double sigma_major, double sigma_minor,
                                     double angle) {
  std::vector<Image> images;
  const double c = std::cos(angle), s = std::sin(angle);
  for (const auto& cam : rc.rig->cameras()) {
    const int w = cam.spec.width, h = cam.spec.height;
    std::vector<float> pixels(static_cast<std::size_t>(w) * h, 0.0f);
    for (const Vec3d& particle : rc.particles) {
      const Vec2d p = cam.model.project(particle);
      for (int y = static_cast<int>(p.y) - 5; y <= static_cast<int>(p.y) + 5; ++y)
        for (int x = static_cast<int>(p.x) - 5; x <= static_cast<int>(p.x) + 5; ++x) {
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          double sum = 0;
          for (int b = 0; b < 6; ++b)
            for (int a = 0; a < 6; ++a) {
              const double dx = x - 0.5 + (a + 0.5) / 6 - p.x, dy = y - 0.5 + (b + 0.5) / 6 - p.y;
              const double r1 = c * dx + s * dy, r2 = -s * dx + c * dy;
              sum += std::exp(-0.5 * (r1 * r1 / (sigma_major * sigma_major) + r2 * r2 / (sigma_minor * sigma_minor)));
            }
          pixels[static_cast<std::size_t>(y) * w + x] += static_cast<float>(1000.0 * sum / 36.0);
        }
    }
    Image image = Image::allocate(w, h, SampleType::f32);
    for (int y = 0; y < h; ++y) std::copy_n(pixels.data() + static_cast<std::size_t>(y) * w, w, image.row<float>(y));
    images.push_back(std::move(image));
  }
  return images;
}

TEST(EllipticalPsf, MatchingTheParticleImagesBeatsRoundWeights) {
  recon_test::ReducedCase rc = recon_test::make_case(64, 20, 80, 0.03, 9);
  const double major = 1.3, minor = 0.75, angle = 0.6;
  rc.images = render_elliptical(rc, major, minor, angle);
  const DenseVolume truth = recon_test::truth_volume(rc.grid, rc.particles);
  recon::ReconstructionOptions o;
  o.algorithm = "fmart";
  o.max_iterations = 6;

  recon::ReconstructionReport report;
  const double q_round = recon_test::quality(recon::make_reconstructor(o)->reconstruct(rc.input(), report), truth);

  // Weights of the image ellipse less the blob's own width (sigma_w^2 = sigma_image^2 -
  // (0.75^2 - 0.5^2), as the default round 0.5 px does for 0.75 px images; reconstructor.h).
  const double blob2 = 0.75 * 0.75 - 0.5 * 0.5;
  recon::PsfSample sample;
  sample.sigma_u_px = std::sqrt(major * major - blob2);
  sample.sigma_v_px = std::sqrt(minor * minor - blob2);
  sample.angle_rad = angle;
  recon::ReconstructionInput input = rc.input();
  input.psf.assign(input.cameras.size(), recon::PsfModel{{sample}});
  const double q_ellipse = recon_test::quality(recon::make_reconstructor(o)->reconstruct(input, report), truth);

  // The same ellipse at the wrong angle (a quarter turn) is worse than the matching one.
  input.psf.assign(input.cameras.size(), recon::PsfModel{{{0.0, sample.sigma_u_px, sample.sigma_v_px, angle - 1.5}}});
  const double q_wrong = recon_test::quality(recon::make_reconstructor(o)->reconstruct(input, report), truth);

  RecordProperty("q_round", std::to_string(q_round));
  RecordProperty("q_ellipse", std::to_string(q_ellipse));
  EXPECT_GT(q_ellipse, q_round + 0.03) << "round " << q_round << ", ellipse " << q_ellipse;
  EXPECT_GT(q_ellipse, q_wrong + 0.03) << "wrong angle " << q_wrong << ", ellipse " << q_ellipse;
}

}  // namespace
