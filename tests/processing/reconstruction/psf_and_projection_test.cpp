// The depth-varying PSF model, the Gaussian weight table and the lattice projection set-up
// against exact projection through the camera model.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "reduced_case.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
// Private headers of the reconstruction, tested directly.
#include "../../../processing/src/reconstruction/grid_projector.h"
#include "../../../processing/src/reconstruction/weight_table.h"

namespace {

using namespace tomorig;

TEST(PsfModel, InterpolatesLinearlyInDepthAndHoldsBeyondTheEnds) {
  const recon::PsfModel psf{{{-1.0, 1.0, 2.0}, {1.0, 0.5, 1.0}}};
  EXPECT_DOUBLE_EQ(psf.at(0.0).sigma_u_px, 0.75);
  EXPECT_DOUBLE_EQ(psf.at(0.0).sigma_v_px, 1.5);
  EXPECT_DOUBLE_EQ(psf.at(-5.0).sigma_u_px, 1.0);
  EXPECT_DOUBLE_EQ(psf.at(5.0).sigma_v_px, 1.0);
  EXPECT_DOUBLE_EQ(psf.max_sigma(), 2.0);
  EXPECT_NO_THROW(psf.validate("psf"));
  EXPECT_THROW(recon::PsfModel{}.validate("psf"), Error);
  EXPECT_THROW(recon::PsfModel::constant(0.0).validate("psf"), Error);
}

TEST(WeightTable, RowsArePixelIntegratedGaussiansAtTheQuantisedPhase) {
  const recon::detail::AxisWeights weights({0.5, 1.0}, 5, 64);
  EXPECT_EQ(weights.levels(), 2);
  for (int slice : {0, 1}) {
    const double sigma = slice == 0 ? 0.5 : 1.0;
    for (float pos : {10.0f, 10.3f, 10.49f, 10.51f, -0.4f}) {
      int start = 0;
      std::uint16_t row = 0;
      weights.locate(pos, slice, start, row);
      const float* w = weights.table() + static_cast<std::size_t>(row) * weights.patch();
      // The patch is centred on the voxel's image: its middle pixel is the nearest one.
      EXPECT_EQ(start + 2, static_cast<int>(std::lround(pos))) << pos;
      for (int a = 0; a < 5; ++a) {
        const double exact = recon::detail::pixel_integrated_gaussian(start + a - pos, sigma);
        // Phase quantised to 1/64 px: at most 1/128 px off, so a weight moves by < 0.01.
        EXPECT_NEAR(w[a], exact, 0.01) << "pos " << pos << " pixel " << start + a;
      }
    }
  }
}

// A pinhole camera with strong radial distortion: far from affine over a few voxels, so the
// lattice must refine (or fall back to exact projection) to stay within tolerance.
class DistortedCamera final : public calibration::CameraModel {
 public:
  explicit DistortedCamera(calibration::PinholeCamera base) : base_(std::move(base)) {}
  std::string model_name() const override { return "distorted"; }
  Vec2d project(const Vec3d& world) const override {
    const Vec2d p = base_.project(world);
    const double dx = p.x - 255.5, dy = p.y - 255.5, r2 = (dx * dx + dy * dy) / (256.0 * 256.0);
    const double f = 1.0 + 0.3 * r2 + 0.2 * std::sin(dx / 3.0);
    return {255.5 + dx * f, 255.5 + dy * f};
  }
  Vec3d back_project(const Vec2d& pixel, double z) const override { return base_.back_project(pixel, z); }
  Ray line_of_sight(const Vec2d& pixel) const override { return base_.line_of_sight(pixel); }
  std::unique_ptr<CameraModel> clone() const override { return std::make_unique<DistortedCamera>(base_); }

 private:
  calibration::PinholeCamera base_;
};

// Max |interpolated - exact| over sampled rows of the grid, pixels.
double worst_row_error(const recon::detail::PreparedInput& in, const recon::detail::GridProjector& projector) {
  const VoxelGrid& g = in.grid;
  std::vector<float> u(g.nx), v(g.nx);
  double worst = 0;
  for (std::size_t c = 0; c < in.camera_count(); ++c)
    for (int k = 0; k < g.nz; k += 7)
      for (int j = 0; j < g.ny; j += 13) {
        projector.row(c, j, k, u.data(), v.data());
        for (int i = 0; i < g.nx; ++i) {
          const Vec2d p = in.cameras[c]->project(g.centre_of(i, j, k));
          worst = std::max(worst, std::hypot(p.x - u[i], p.y - v[i]));
        }
      }
  return worst;
}

recon::detail::PreparedInput thesis_input(const std::vector<const calibration::CameraModel*>& cameras) {
  recon::detail::PreparedInput in;
  in.grid = sim::find_case("tpiv-thesis").grid;
  in.cameras = cameras;
  in.threads = 2;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    recon::detail::CameraImage image;
    image.width = image.height = 512;
    in.images.push_back(image);
  }
  return in;
}

TEST(GridProjector, LatticeMatchesExactProjectionOnTheThesisGrid) {
  std::vector<calibration::PinholeCamera> models;
  for (const auto& spec : sim::find_case("tpiv-thesis").cameras)
    models.push_back(calibration::PinholeCamera::yawed(spec.yaw_deg, spec.focal_length_mm, spec.pixel_pitch_um,
                                                       spec.distance_mm, spec.width, spec.height));
  std::vector<const calibration::CameraModel*> cameras;
  for (const auto& m : models) cameras.push_back(&m);
  const recon::detail::PreparedInput in = thesis_input(cameras);
  const recon::detail::GridProjector projector(in);
  EXPECT_GT(projector.step(0), 1);  // a pinhole camera needs no per-voxel projection
  EXPECT_LT(worst_row_error(in, projector), 0.01);
}

TEST(GridProjector, DistortingModelStillProjectsWithinTolerance) {
  const DistortedCamera camera(calibration::PinholeCamera::yawed(30, 100, 7.4, 263.16, 512, 512));
  recon::detail::PreparedInput in = thesis_input({&camera});
  in.grid = VoxelGrid::centred(256, 256, 80, 0.039);  // the same volume, coarser: a quicker check
  const recon::detail::GridProjector projector(in);
  EXPECT_LT(projector.step(0), 16);  // the coarse lattice was not good enough
  EXPECT_LT(worst_row_error(in, projector), 0.01);
}

}  // namespace
