#pragma once
// Does a set of calibration points determine a model's mapping? A polynomial (or rational)
// model is fixed by its values on the points only if no combination of its monomials vanishes
// on all of them: points on three lines, for instance, lie on a quadric, so a quadratic
// numerator or denominator can change by that quadric without changing any residual, and the
// fitted mapping is arbitrary between the lines. These checks name the monomials the points
// do not determine, describe the point layout, and list the models the points do determine.
#include <span>
#include <string>
#include <vector>

#include "polynomial_maps.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration::detail {

struct BasisCheck {
  bool determined = true;
  // Monomials (in world x, y, z) that are a combination of lower-order ones on the points,
  // in order of increasing degree, e.g. {"y²", "yz", "z²"}.
  std::vector<std::string> undetermined_terms;
  // For the first undetermined monomial: "y² is a combination of 1, y, z".
  std::string combination;
};

// Rank of the monomial design matrix of `basis` over the normalised world points (columns
// scaled to unit length, greedy Gram-Schmidt in order of increasing degree).
BasisCheck check_basis(Basis basis, std::span<const PointCorrespondence> points, const Normalization& n);

// "the 45 points lie on 3 lines parallel to x" when they do (lines along a world axis), else
// "the points do not fill the volume (they lie on a few lines or on a curved surface)".
std::string describe_layout(std::span<const PointCorrespondence> points);

// The models of camera_model_names() that the points determine (rank of each model's basis
// and its plane count), e.g. {"pinhole", "dlt"}.
std::vector<std::string> determined_models(std::span<const PointCorrespondence> points, const Normalization& n);

// Throws bad_input naming the camera, the undetermined terms and a model that is determined,
// if `basis` is not determined by the points.
void require_determined(Basis basis, const std::string& model, std::span<const PointCorrespondence> points,
                        const Normalization& n, const FitOptions& options);

// After a rational fit: throws bad_input if the denominator of `coefficients` changes sign (a
// pole) over the box spanned by the samples' inputs (sampled on a dense lattice), naming where.
// A zero of the denominator shared by the numerators (a common factor, which a ratio's fit
// may pick up freely) is not a pole: the mapping must also leave the image there.
void require_one_signed_denominator(const MapForm& form, const std::vector<double>& coefficients,
                                    const MapSamples& samples, const std::string& model, const std::string& what,
                                    const Normalization& n, bool world_inputs, std::span<const PointCorrespondence> points,
                                    const FitOptions& options);

}  // namespace tomorig::calibration::detail
