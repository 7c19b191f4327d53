#pragma once
// Turning a validated field into the predictor of the next pass: holes filled from their
// neighbours, then a 3x3x3 Gaussian low-pass, which damps the instability of iterative
// deformation at high overlap (thesis Sect. 2.5, ref. [148]).
#include "tomorig/core/vector_field.h"

namespace tomorig::piv::detail {

// Invalid vectors take the mean of their non-invalid 26-neighbours, repeated until every hole
// is filled (0 where the whole field is invalid). Statuses are left unchanged.
void fill_invalid(VectorField& field);

// Separable (1 2 1)/4 filter per axis, renormalised at the boundary.
void smooth_gaussian3(VectorField& field);

}  // namespace tomorig::piv::detail
