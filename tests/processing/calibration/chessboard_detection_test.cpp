// detect_chessboard against the calib-thesis simulator's truth: sub-pixel accuracy on blurred,
// noisy, anti-aliased renderings, partial boards, orientation, and bad input.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/target_detection.h"
#include "tomorig/simulators/calibration_target.h"

namespace tomorig::calibration {
namespace {

struct Errors {
  double mean = 0, max = 0, bias_x = 0, bias_y = 0;
  int n = 0;
};

// Detected pixels against where the true camera sees each identified corner.
Errors compare(const sim::CalibTargetCase& c, std::size_t cam, std::size_t plane, const TargetDetection& d) {
  Errors e;
  for (const PointCorrespondence& p : d.points) {
    const int i = static_cast<int>(std::lround(p.world.x / c.board.square_mm));
    const int j = static_cast<int>(std::lround(p.world.y / c.board.square_mm));
    const Vec2d t = c.corner_pixel(cam, i, j, plane);
    const double dx = p.pixel.x - t.x, dy = p.pixel.y - t.y;
    const double r = std::hypot(dx, dy);
    e.mean += r, e.max = std::max(e.max, r), e.bias_x += dx, e.bias_y += dy;
    ++e.n;
  }
  if (e.n) e.mean /= e.n, e.bias_x /= e.n, e.bias_y /= e.n;
  return e;
}

sim::CalibTargetCase reduced_case(std::uint64_t seed = 5) {
  sim::CalibTargetOptions o;
  o.reduced = true;
  o.seed = seed;
  return sim::make_calib_thesis_case(o);
}

TEST(ChessboardDetection, CornersMatchTruthToSubPixelOnAllViews) {
  const sim::CalibTargetCase c = reduced_case();
  for (std::size_t cam = 0; cam < c.cameras.size(); ++cam)
    for (std::size_t plane : {std::size_t{0}, std::size_t{6}}) {
      const Image img = sim::render_target_view(c, cam, plane);
      const TargetDetection d = detect_chessboard(img, c.board, c.planes[plane].z_nominal_mm, "test");
      const Errors e = compare(c, cam, plane, d);
      std::printf("cam %zu plane %zu: %d corners, mean %.4f px, max %.4f px, bias (%.4f, %.4f)\n", cam, plane, e.n,
                  e.mean, e.max, e.bias_x, e.bias_y);
      EXPECT_GT(e.n, 300) << "camera " << cam << " plane " << plane;
      EXPECT_LT(e.mean, 0.02) << "camera " << cam << " plane " << plane;
      EXPECT_LT(std::hypot(e.bias_x, e.bias_y), 0.005) << "camera " << cam << " plane " << plane;
      EXPECT_LT(e.max, 0.06) << "camera " << cam << " plane " << plane;
      for (const PointCorrespondence& p : d.points) EXPECT_EQ(p.world.z, c.planes[plane].z_nominal_mm);
    }
}

// A copy of columns [x0, x1) of a u16 image.
Image crop_columns(const Image& in, int x0, int x1) {
  Image out = Image::allocate(x1 - x0, in.height(), SampleType::u16);
  for (int y = 0; y < in.height(); ++y)
    for (int x = x0; x < x1; ++x) out.at<std::uint16_t>(x - x0, y) = in.at<std::uint16_t>(x, y);
  return out;
}

TEST(ChessboardDetection, PartialBoardIsIdentifiedByItsVisibleEdge) {
  const sim::CalibTargetCase c = reduced_case();
  const std::size_t cam = 1, plane = 3;
  const Image full = sim::render_target_view(c, cam, plane);
  // Cut the left part of the board away: the right edge still tells which corner is which.
  const Vec2d left = c.corner_pixel(cam, 0, 10, plane), right = c.corner_pixel(cam, 21, 10, plane);
  const int x0 = static_cast<int>(left.x + 0.4 * (right.x - left.x));
  const TargetDetection d = detect_chessboard(crop_columns(full, x0, full.width()), c.board, 0.0, "cropped");
  ASSERT_GT(d.points.size(), 150u);
  EXPECT_FALSE(d.warnings.empty());  // the missing corners are reported
  double worst = 0;
  for (const PointCorrespondence& p : d.points) {
    const int i = static_cast<int>(std::lround(p.world.x / c.board.square_mm));
    const int j = static_cast<int>(std::lround(p.world.y / c.board.square_mm));
    EXPECT_GE(i, 7);
    const Vec2d t = c.corner_pixel(cam, i, j, plane);
    worst = std::max(worst, std::hypot(p.pixel.x + x0 - t.x, p.pixel.y - t.y));
  }
  EXPECT_LT(worst, 0.1);  // every corner got its true identity (a wrong one is >= 1 square off)

  // Cut on both sides: no corner can be identified, and detection says so instead of guessing.
  const int x1 = static_cast<int>(left.x + 0.8 * (right.x - left.x));
  try {
    detect_chessboard(crop_columns(full, x0, x1), c.board, 0.0, "camera 2, plane z = 0 mm");
    FAIL() << "a board cut on both sides must not be identified";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("camera 2, plane z = 0 mm"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cannot be identified"), std::string::npos) << e.what();
  }
}

TEST(ChessboardDetection, OriginIsTopLeftAsSeenAndXPointsRight) {
  const sim::CalibTargetCase c = reduced_case();
  const std::size_t cam = 0, plane = 3;
  const Image img = sim::render_target_view(c, cam, plane);
  // The same view turned by 180 degrees: the board's far corner is now top-left, so it
  // becomes the origin, and the identities follow the convention, not the print.
  Image turned = Image::allocate(img.width(), img.height(), SampleType::u16);
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      turned.at<std::uint16_t>(img.width() - 1 - x, img.height() - 1 - y) = img.at<std::uint16_t>(x, y);
  for (bool is_turned : {false, true}) {
    const TargetDetection d = detect_chessboard(is_turned ? turned : img, c.board, 0.0, "test");
    ASSERT_GT(d.points.size(), 300u);
    double worst = 0;
    for (const PointCorrespondence& p : d.points) {
      int i = static_cast<int>(std::lround(p.world.x / c.board.square_mm));
      int j = static_cast<int>(std::lround(p.world.y / c.board.square_mm));
      Vec2d seen = p.pixel;
      if (is_turned) {
        i = c.board.inner_corners_x - 1 - i, j = c.board.inner_corners_y - 1 - j;
        seen = {img.width() - 1 - seen.x, img.height() - 1 - seen.y};
      }
      const Vec2d t = c.corner_pixel(cam, i, j, plane);
      worst = std::max(worst, std::hypot(seen.x - t.x, seen.y - t.y));
    }
    EXPECT_LT(worst, 0.1) << (is_turned ? "turned view" : "upright view");
    // x grows to the right and y downwards in the image it was detected in.
    const PointCorrespondence& first = d.points.front();
    for (const PointCorrespondence& p : d.points) {
      if (p.world.y == first.world.y && p.world.x > first.world.x) { EXPECT_GT(p.pixel.x, first.pixel.x); }
      if (p.world.x == first.world.x && p.world.y > first.world.y) { EXPECT_GT(p.pixel.y, first.pixel.y); }
    }
  }
}

TEST(ChessboardDetection, RefusesBadSpecAndEmptyImages) {
  const Image grey = Image::allocate(64, 64, SampleType::u16);
  EXPECT_THROW(detect_chessboard(grey, {22, 21, 0.75}, 0.0, "flat"), Error);
  EXPECT_THROW(detect_chessboard(grey, {1, 21, 0.75}, 0.0, "spec"), Error);
  EXPECT_THROW(detect_chessboard(grey, {22, 21, 0.0}, 0.0, "spec"), Error);
  EXPECT_THROW(detect_chessboard(Image{}, {22, 21, 0.75}, 0.0, "empty"), Error);
}

}  // namespace
}  // namespace tomorig::calibration
