#pragma once
// Volume operations of the multi-grid and deformation passes (thesis Sect. 2.5, 5.4.3):
// binning by summing N^3 voxels, cubic B-spline prefiltering, and the symmetric deformation
// of Eq. 2.17.
#include <cstdint>
#include <vector>

#include "correlation/volume_view.h"
#include "tomorig/core/vector_field.h"
#include "tomorig/processing/correlation/correlation_options.h"

namespace tomorig::piv::detail {

// Sums blocks of factor^3 voxels; the result has floor(n / factor) voxels per axis.
// Into `out`, reusing its memory.
void downsample_sum(const VolumeView& v, int factor, int threads, std::vector<float>& out);

// The interpolating cubic B-spline coefficients of `samples` (Unser's recursive filter, mirror
// boundaries), so that the spline passes through the samples. Into `out`, reusing its memory.
void bspline_coefficients(const VolumeView& samples, int threads, std::vector<float>& out);

// Where a volume has signal: 1 for voxels within `radius` voxels (Chebyshev) of a sample whose
// magnitude exceeds `relative_threshold` times `largest` (the volume's largest magnitude), else 0.
// Into `out`, with `scratch` for the intermediate dilation (both reuse their memory).
void signal_support(const VolumeView& v, float relative_threshold, float largest, int radius, int threads,
                    std::vector<std::uint8_t>& out, std::vector<std::uint8_t>& scratch);

// Where deform_pair evaluates samples: within kSupportRadius voxels of a source voxel above
// kSupportThreshold of the volume's largest magnitude. A sample's value is, to within the cubic
// interpolant's small outer lobes, a blend of the two source voxels bracketing it on each axis,
// and both lie within one voxel of its nearest voxel; beyond that the sample is a lobe of a
// faint blob edge, below the threshold at which the direct correlation lists a voxel
// (kOccupiedThreshold), so it is 0 without evaluating its 64 taps. The support threshold is a
// third of the listing threshold: the margin for the interpolant's overshoot.
// Measured on the tpiv-thesis FMART pair at 0.05 ppp (docs/correlation.md, "Speed", sixth
// round): radius 1 instead of 2 cut the second deformation pass's deformation from 0.56 to
// 0.33 s and left every accuracy figure of `bench piv3d` (truth and FMART, 0.05 and 0.10 ppp)
// unchanged to the printed digits.
inline constexpr float kSupportThreshold = 1e-3f;
inline constexpr int kSupportRadius = 1;

// Eq. 2.17 on a volume binned by `factor`: out_a(x) = a(x - d(x)/2), out_b(x) = b(x + d(x)/2),
// with d the predictor (voxels of the full grid, node centres in full-grid voxel coordinates)
// interpolated trilinearly at each voxel. `a`/`b` are samples for trilinear interpolation or
// B-spline coefficients for cubic interpolation. Outside the volume the intensity is 0.
// `support_a` / `support_b` (signal_support of the samples, may be empty: everywhere) mark
// where a sample can be non-zero; elsewhere the output is 0 and not interpolated.
// Returns the largest magnitude of each deformed volume (found row by row as they are written).
struct DeformedLargest {
  float a = 0.0f, b = 0.0f;
};
DeformedLargest deform_pair(const VolumeView& a, const VolumeView& b, const VectorField& predictor, int factor,
                            Interpolation interpolation, std::vector<float>& out_a, std::vector<float>& out_b,
                            int threads, const std::vector<std::uint8_t>& support_a = {},
                            const std::vector<std::uint8_t>& support_b = {});

// The predictor at a full-grid voxel position: trilinear between nodes, linearly extrapolated
// from the end cell up to one node spacing beyond the outermost nodes, constant further out.
Vec3f sample_field(const VectorField& field, double x, double y, double z);

// sample_field's cell and fraction along one axis.
void locate_axis(double p, double origin, double spacing, int n, int& i0, double& frac);

// sample_field along one row of voxels: the y-z interpolation is done once per row (set_row),
// leaving a linear interpolation in x per voxel.
class RowPredictor {
 public:
  explicit RowPredictor(const VectorField& field) : f_(field) {}
  void set_row(double y, double z);
  Vec3f at(double x) const;
  // After set_row: x, y, z of the displacement per x-node, interpolated at the row's y, z.
  const double* columns() const { return columns_.data(); }

 private:
  const VectorField& f_;
  std::vector<double> columns_;  // per x-node: the displacement interpolated at the row's y, z
};

}  // namespace tomorig::piv::detail
