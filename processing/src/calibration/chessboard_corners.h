#pragma once
// Internal to the chessboard detector: finding X-corner candidates in an image and refining
// them to sub-pixel accuracy. OpenCV stays in the .cpp files.
#include <cmath>
#include <cstddef>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"

namespace tomorig::calibration::chessboard {

inline Vec2d operator+(const Vec2d& a, const Vec2d& b) { return {a.x + b.x, a.y + b.y}; }
inline Vec2d operator-(const Vec2d& a, const Vec2d& b) { return {a.x - b.x, a.y - b.y}; }
inline Vec2d operator*(double s, const Vec2d& a) { return {s * a.x, s * a.y}; }
inline double dot(const Vec2d& a, const Vec2d& b) { return a.x * b.x + a.y * b.y; }
inline double length(const Vec2d& a) { return std::sqrt(dot(a, a)); }

// The image as float samples scaled so that the board's dark squares are ~0 and its light
// squares ~1 (robust percentiles), row-major, width x height.
struct GreyImage {
  int width = 0, height = 0;
  std::vector<float> pixels;
  float at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
  // Bilinear sample; the caller keeps (x, y) inside [0, width-1] x [0, height-1].
  double sample(double x, double y) const;
};

GreyImage normalised_grey(const Image& image);

struct Candidate {
  Vec2d pixel;
  double response = 0;  // saddle strength (smoothed -det Hessian)
};

// Saddle points that look like chessboard X-corners: a strong negative Hessian determinant
// and, on a ring around them, four alternating dark/light sectors with opposite sectors alike
// (which rejects the L-shaped corners at the board's outer edge). Also returns the typical
// spacing of the candidates (median nearest-neighbour distance, pixels) via `spacing_px`.
std::vector<Candidate> find_x_corner_candidates(const GreyImage& grey, double& spacing_px);

// Sign (+1/-1) of the X-corner at `p` whose lattice steps are `step_a` and `step_b`: which
// diagonal pair of quadrants is light. Neighbouring corners of a chessboard have opposite
// polarity. 0 if the quadrants cannot be told apart or lie outside the image.
int corner_polarity(const GreyImage& grey, const Vec2d& p, const Vec2d& step_a, const Vec2d& step_b);

// Refines a corner to sub-pixel accuracy by fitting a blurred X-junction to the pixels within
// `radius` (which must keep the window inside the four squares meeting at the corner):
// I = c + a erf(d1 / (sqrt2 s)) erf(d2 / (sqrt2 s)), with d1, d2 the signed distances to the
// two board lines through the corner, started along the lattice steps `line_a`, `line_b`.
// The model is point-symmetric about the corner like the true blurred pattern, so its
// mismatch does not shift the centre. Returns false if the fit fails or leaves the window.
bool refine_corner(const GreyImage& grey, Vec2d& p, const Vec2d& line_a, const Vec2d& line_b, double radius);

}  // namespace tomorig::calibration::chessboard
