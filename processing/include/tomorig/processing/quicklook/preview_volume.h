#pragma once
// Preview volume (issue 16, item 3): a coarse reconstruction of the newest set, fast enough to
// follow a running rig, and what an operator reads from it: maximum-intensity projections, the
// intensity against depth with the light sheet's position and thickness, the ghost level in
// front of and behind the sheet (thesis Fig. 5.9) and a reconstruction signal-to-noise ratio
// (thesis Sect. 3.2.2).
//
// The images are binned (2 x 2 by default) and reconstructed with MLOS (or MENT) through the
// reconstruction module as it is, on a grid of binned voxels: the rig's grid with voxels
// `binning` times larger, and `depth_factor` times deeper, so that the sheet is found even
// when it sits off the grid's centre and the ghost level is read outside it. A binned pixel
// sees about what a binned voxel does, as a full pixel sees a full voxel.
//
// A stage keeps one PreviewVolume for the run (it holds the binned cameras, the grid and which
// voxels every camera sees) and one PreviewResult, and calls reconstruct() with one exposure of
// all cameras whenever it is free (it may skip sets: the cost is tens of milliseconds on the
// tpiv-thesis rig, bench/quicklook_benchmark.cpp). Not thread-safe.
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/core/volume.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"
#include "tomorig/processing/quicklook/targets.h"

namespace tomorig::quicklook {

struct PreviewVolumeOptions {
  std::string algorithm = "mlos";  // "mlos" (one pass) or "ment" (iterated pseudo-images)
  int ment_iterations = 2;         // MENT only, 1 to 20
  int binning = 2;                 // image pixels (and rig voxels) per preview pixel along each axis, 1 to 8
  // Preview grid depth over the rig grid's depth (>= 1): room around the sheet for the ghost
  // level and for a sheet that is not where the grid expects it.
  double depth_factor = 2.0;
  // A binned pixel below this fraction of its image's maximum counts as empty for MLOS. Higher
  // than a full reconstruction's 0.05: binned images are four times denser, and at 0.05 a
  // third of the grid would be active (ghosts), at 0.15 a tenth, with the sheet as clear.
  double mlos_threshold = 0.15;
  double sigma_px = 0.5;  // Gaussian sigma of the voxel-to-pixel weights, binned pixels
  int threads = 1;        // reconstruction threads (the preview shares the machine with the recorder)

  // Throws tomorig::Error (bad_input) naming the field, its value and what is allowed.
  void validate() const;
};

// The light sheet as the depth profile shows it (thesis Fig. 5.9). The profile is the mean
// reconstructed intensity per voxel of each z-slice, over the voxels every camera sees,
// normalised by its maximum. The sheet is the run of slices around the maximum above half way
// between the ghost level outside and the level inside; its edges are the half-way crossings,
// interpolated between slices. MLOS and MENT make a voxel the product of what every camera
// sees there, so the reconstructed intensity of a particle goes as the light to the power of
// the camera count: a sheet with sharp edges reads as thick as it is, one with soft edges
// thinner than between its 50 % light points (docs/quicklook.md: tpiv-thesis, 4 cameras, a
// top-hat sheet with edges of 5 % of its thickness reads 9 % thin).
struct SheetProfile {
  std::vector<double> z_mm;       // world z of each slice centre
  std::vector<double> intensity;  // per slice, relative to the maximum; NaN where no camera sees enough
  bool found = false;             // a sheet with both edges inside the preview grid
  double position_mm = not_measured;   // world z half way between the edges
  double thickness_mm = not_measured;  // between the edges
  double low_edge_mm = not_measured, high_edge_mm = not_measured;
  // Mean relative level of the slices in front of (on the cameras' side) and behind the
  // sheet, beyond `noise_margin_slices` from its edges; NaN if no slice is there.
  double ghost_front = not_measured, ghost_back = not_measured;
  // Reconstruction SNR: the mean level inside the sheet over the mean level outside it.
  double rsnr = not_measured;
  // green: a sheet inside the rig's grid; amber: a sheet reaching beyond it (the reconstruction
  // volume misses part of the light); red: no sheet found.
  Flag flag = Flag::red;
};

struct SheetAnalysisOptions {
  double noise_margin_slices = 2.25;  // slices next to an edge left out of the ghost level (as quality::reconstruction_snr)
  bool cameras_at_low_z = true;       // which side is the front
  double grid_low_z_mm = 0, grid_high_z_mm = 0;  // the rig grid's depth, for the flag (both 0: not judged)
};

// The sheet in a depth profile: `mean_intensity[k]` for slice k at z = z0_mm + k * dz_mm (NaN
// for slices not measured). Pure function, for tests and for profiles made elsewhere.
SheetProfile analyse_depth_profile(std::span<const double> mean_intensity, double z0_mm, double dz_mm,
                                   const SheetAnalysisOptions& options = {});

struct PreviewResult {
  VoxelGrid grid;        // the preview grid
  SparseVolume volume;   // the preview volume itself (kept for callers that store or re-slice it)
  // Maximum-intensity projections as float images (quicklook::max_projection conventions):
  // along z (nx x ny: the sheet seen face on), along y (nx x nz) and along x (ny x nz).
  Image mip_z, mip_y, mip_x;
  SheetProfile sheet;
  std::size_t active_voxels = 0;
  double reconstruction_seconds = 0;  // the reconstruction alone
  double seconds = 0;                 // binning, reconstruction, projections and profile
};

class PreviewVolume {
 public:
  // `cameras`: the rig's models (full-resolution pixels), `sizes`: their sensor sizes, `rig_grid`:
  // the rig's reconstruction grid. Works out the binned cameras, the preview grid and the
  // voxels every camera sees. Throws tomorig::Error (bad_input) for invalid options, no
  // cameras, mismatched lists, an empty grid, or a grid no camera sees.
  PreviewVolume(std::vector<std::shared_ptr<const calibration::CameraModel>> cameras,
                std::vector<calibration::ImageSize> sizes, const VoxelGrid& rig_grid,
                const PreviewVolumeOptions& options = {});
  ~PreviewVolume();
  PreviewVolume(PreviewVolume&&) noexcept;
  PreviewVolume& operator=(PreviewVolume&&) noexcept;

  const PreviewVolumeOptions& options() const { return options_; }
  const VoxelGrid& grid() const;  // the preview grid

  // Reconstructs one exposure (one image per camera, in camera order, full resolution, u8, u16
  // or f32). `backgrounds`: each camera's background level in counts, subtracted before
  // reconstructing (e.g. FrameStatistics::background); empty: a low percentile of each binned
  // image. Throws tomorig::Error (bad_input) for a wrong number or size of images or an image
  // without light; runtime errors of the reconstruction pass through.
  void reconstruct(std::span<const Image> images, PreviewResult& out, std::span<const double> backgrounds = {});

 private:
  struct Work;
  PreviewVolumeOptions options_;
  std::unique_ptr<Work> work_;
};

}  // namespace tomorig::quicklook
