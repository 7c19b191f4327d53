#pragma once
// Volume operations of the multi-grid and deformation passes (thesis Sect. 2.5, 5.4.3):
// binning by summing N^3 voxels, cubic B-spline prefiltering, and the symmetric deformation
// of Eq. 2.17.
#include <vector>

#include "correlation/volume_view.h"
#include "tomorig/core/vector_field.h"
#include "tomorig/processing/correlation/correlation_options.h"

namespace tomorig::piv::detail {

// Sums blocks of factor^3 voxels; the result has floor(n / factor) voxels per axis.
std::vector<float> downsample_sum(const VolumeView& v, int factor, int threads);

// In-place interpolating cubic B-spline coefficients (Unser's recursive filter, mirror
// boundaries), so that the spline passes through the samples.
void bspline_prefilter(std::vector<float>& values, int nx, int ny, int nz, int threads);

// Eq. 2.17 on a volume binned by `factor`: out_a(x) = a(x - d(x)/2), out_b(x) = b(x + d(x)/2),
// with d the predictor (voxels of the full grid, node centres in full-grid voxel coordinates)
// interpolated trilinearly at each voxel. `a`/`b` are samples for trilinear interpolation or
// B-spline coefficients for cubic interpolation. Outside the volume the intensity is 0.
void deform_pair(const VolumeView& a, const VolumeView& b, const VectorField& predictor, int factor,
                 Interpolation interpolation, std::vector<float>& out_a, std::vector<float>& out_b, int threads);

// The predictor at a full-grid voxel position: trilinear between nodes, linearly extrapolated
// from the end cell up to one node spacing beyond the outermost nodes, constant further out.
Vec3f sample_field(const VectorField& field, double x, double y, double z);

}  // namespace tomorig::piv::detail
