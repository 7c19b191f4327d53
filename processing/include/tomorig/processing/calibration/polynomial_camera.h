#pragma once
// Higher-order camera models of thesis Appendix A.2.2, both working in normalised coordinates
// (Appendix A.1) and both with a fitted inverse mapping (pixel + z -> world x, y):
//
//  "rational2"  ratios of 2nd-order polynomials (Eq. A.4, Willert). Per mapping 30
//               coefficients: numerator of the first output (10), of the second (10), the
//               shared denominator (10), each over the monomials
//               [p^2, pq, pr, p, q^2, qr, q, r^2, r, 1] of the inputs (p, q, r) - the order
//               of b_k1..b_k10 in Eq. A.4. The denominator's constant is fixed to 1.
//  "soloff3"    3rd-order polynomials (Eq. A.5, Soloff). Per mapping 40 coefficients: 20 for
//               each output over [1, p, q, r, p^2, q^2, r^2, pq, pr, qr, p^3, q^3, r^3, p^2q,
//               p^2r, q^2p, q^2r, r^2p, pqr, r^2q]: the 19 monomials printed in Eq. A.5 plus
//               r^2q, which completes the cubic (Eq. A.5 has r^2p but not r^2q). Needs points
//               on >= 4 planes (the r^3 term).
//
// Forward mapping inputs are normalised world (x~, y~, z~), outputs normalised pixel
// (x~_I, y~_I); the inverse mapping's inputs are (x~_I, y~_I, z~), outputs (x~, y~).
#include <vector>

#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

enum class PolynomialKind { rational2, soloff3 };

class PolynomialCamera final : public CameraModel {
 public:
  // Coefficients per mapping: 30 (rational2) or 40 (soloff3).
  static int coefficient_count(PolynomialKind kind);

  // Throws tomorig::Error (bad_input) if a coefficient count is wrong, a coefficient or the
  // normalisation is not finite, or a scale is not > 0. newton_steps: see FitOptions.
  PolynomialCamera(PolynomialKind kind, const Normalization& normalization, std::vector<double> forward,
                   std::vector<double> inverse, int newton_steps = 4);

  PolynomialKind kind() const { return kind_; }
  const Normalization& normalization() const { return normalization_; }
  const std::vector<double>& forward_coefficients() const { return forward_; }
  const std::vector<double>& inverse_coefficients() const { return inverse_; }
  int newton_steps() const { return newton_steps_; }

  // The fitted inverse mapping alone: world (x, y, world_z) for a pixel, no Newton polish.
  Vec3d inverse_mapping(const Vec2d& pixel, double world_z) const;

  std::string model_name() const override;
  Vec2d project(const Vec3d& world) const override;
  // inverse_mapping(), then up to newton_steps Newton steps on project() in (x, y), so that
  // project(back_project(p, z)) == p to ~1e-9 px inside the calibrated volume.
  Vec3d back_project(const Vec2d& pixel, double world_z) const override;
  // Through back_project() at the normalised depths z~ = -1 and +1 (about the outer
  // calibration planes); origin at z~ = -1, direction towards increasing world z.
  Ray line_of_sight(const Vec2d& pixel) const override;
  std::unique_ptr<CameraModel> clone() const override;

 private:
  PolynomialKind kind_;
  Normalization normalization_;
  std::vector<double> forward_, inverse_;
  int newton_steps_;
};

}  // namespace tomorig::calibration
