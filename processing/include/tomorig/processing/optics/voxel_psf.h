#pragma once
// The knife-edge PSF measured in voxel space, as thesis Sect. 6.4 and 7.3.3 do it: a camera's
// chessboard calibration image is back-projected onto the x-y voxel plane of its depth
// (bilinear interpolation between the 4 neighbouring pixels, as a reconstruction reads the
// image), flat-fielded with the bright and dark squares, and the edges along one plane axis
// give the edge spread across them, differentiated to the line spread and fitted with a
// Gaussian of half-width chi (edge_psf.h). The result therefore includes the smoothing of the
// back-projection (the thesis's reason to measure there); the camera's own PSF follows by
// removing the bilinear interpolation's known spread.
//
//   optics::VoxelPlane plane{-4.0, -4.0, z, 0.029, 276, 276};   // x0, y0, z, voxel, nx, ny
//   optics::VoxelPsf psf = optics::measure_voxel_psf(image, camera_model, plane);
//   psf.chi_voxel_um   // Fig. 6.15 / 7.9's quantity
//   psf.chi_um         // the camera's PSF (optics + pixel), object um: for the visibility model
//   psf.sigma_px()     // the reconstruction's weight sigma in pixels (psf_model.h)
#include <vector>

#include "tomorig/core/image.h"

namespace tomorig::calibration {
class CameraModel;
}

namespace tomorig::optics {

// An x-y plane of voxels at depth z: voxel centres at (x0 + i voxel, y0 + j voxel, z), world mm.
struct VoxelPlane {
  double x0_mm = 0, y0_mm = 0, z_mm = 0;
  double voxel_mm = 0;
  int nx = 0, ny = 0;
  // Throws bad_input naming the field: voxel <= 0, fewer than 32 voxels a side, non-finite.
  void validate() const;
};

// The direction of the spread: across the board lines running along x (the spread along y,
// Fig. 6.15), or across those running along y.
enum class SpreadAxis { x, y };

// Back-projection of `image` onto the plane: an f32 image of nx x ny (row j is y0 + j voxel),
// each voxel the bilinear interpolation of the pixels around its image. Throws bad_input if a
// voxel is imaged outside the picture (naming the plane's corner and the image size).
Image back_project_plane(const Image& image, const calibration::CameraModel& camera, const VoxelPlane& plane);

// Flat-field correction of a back-projected chessboard of squares `square_px` wide:
// (I - dark) / (bright - dark), the dark and bright levels the 10th and 90th percentiles of
// windows 2.5 squares wide (both colours in each) on a grid a square apart, interpolated
// bilinearly between them - the thesis's Kriging of the square centres, for a slowly varying
// back light. Throws bad_input if a window has no contrast.
Image flat_field_chessboard(const Image& plane_image, double square_px);

struct ImageSize {
  int width = 0, height = 0;
};

// The default plane: the largest square centred on the z axis that every camera sees at every
// depth (with a 10 % margin), at about one voxel per pixel (the finest camera's object pixel at
// the middle depth; the thesis's 60 voxel/mm). z is left 0. Throws bad_input if the cameras
// share no view of the axis.
VoxelPlane common_view_plane(const std::vector<const calibration::CameraModel*>& cameras,
                             const std::vector<ImageSize>& sizes, const std::vector<double>& z_mm);

struct VoxelPsf {
  double chi_voxel_um = 0;  // LSF half-width in the voxel plane, as measured, along the spread
  double chi_um = 0;        // the camera's own (optics + pixel): interpolation removed, object um
  double chi_px = 0;        // the same in the camera's pixels
  double object_pixel_um = 0;  // one pixel in object space at the plane's centre (unforeshortened)
  double square_voxels = 0;    // the board's square size found in the plane, voxels
  int edges = 0;               // edge segments measured
  double rms_residual = 0;     // of the Gaussian fit to the pooled line spread, relative to its peak
  // The Gaussian sigma of the reconstruction's pixel-integrated weights (psf_model.h): the
  // camera's PSF without the pixel's own box, sqrt((chi_px / 2)^2 - 1/12).
  double sigma_px() const;
};

// Back-projects, flat-fields and measures. Throws bad_input if the plane leaves the image or
// holds no measurable board edge (the message says what to change).
VoxelPsf measure_voxel_psf(const Image& image, const calibration::CameraModel& camera, const VoxelPlane& plane,
                           SpreadAxis axis = SpreadAxis::y);

}  // namespace tomorig::optics
