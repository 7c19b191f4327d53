#pragma once
// Image positions of voxel centres, for any CameraModel, without a virtual call per voxel.
//
// Per camera, the model's project() is evaluated exactly on a coarse 3-D lattice of voxel
// centres (every `step` voxels along each axis) and interpolated trilinearly in between. The
// interpolation error is measured at the centre of every lattice cell against the exact
// projection; if it exceeds the tolerance the lattice is refined, down to step 2, and below
// that every voxel is projected exactly. So a pinhole camera (smooth, nearly affine over a few
// voxels) uses a coarse lattice, and a strongly distorting model still gets the right answer.
#include <cstddef>
#include <vector>

#include "prepared_input.h"

namespace tomorig::recon::detail {

class GridProjector {
 public:
  // Throws tomorig::Error (bad_input) if some camera sees none of the grid.
  explicit GridProjector(const PreparedInput& in, double tolerance_px = 0.01);

  // Pixel positions (u, v) in camera c of voxels (0 .. nx-1, j, k).
  void row(std::size_t c, int j, int k, float* u, float* v) const;

  // Pixel positions in camera c of the listed voxels (i = voxels[0 .. count-1], row j, slice
  // k), written to u[i], v[i]: what row() gives there, without filling the whole row.
  void row_at(std::size_t c, int j, int k, const int* voxels, int count, float* u, float* v) const;

  // The linear segments of row (j, k) in camera c, for kernels that compute positions
  // themselves: voxel i of segment a, i in [a * step, a * step + length), is at
  // u = u0[a] + du[a] * (i - a * step), v likewise -- the arithmetic of row(), so the positions
  // are the same to the bit. The last segment ends at nx. Each array needs max_segments()
  // entries (u0 and v0 also receive the row's last node). Returns the number of segments; 0
  // for exact projection (step 1).
  int row_segments(std::size_t c, int j, int k, float* u0, float* du, float* v0, float* dv) const;
  // The same for the line through fractional row and slice positions: j + dj and k + dk, with
  // dj, dk in [0, 1] and the points j, j + 1 (k, k + 1) in the same lattice cell, as for the
  // centre of a 2 x 2 block of rows (j even, the step even): the average of the four rows.
  int row_segments(std::size_t c, int j, int k, float dj, float dk, float* u0, float* du, float* v0, float* dv) const;
  int max_segments() const;

  // The largest change of the interpolated positions in camera c per voxel step along i, j
  // and k (pixels): a bound on how far apart the images of neighbouring voxels can be, for
  // conservative coarse tests. `defined` is false for exact projection (step 1) and where a
  // lattice node lies behind the camera (the interpolant is meaningless there).
  struct Slopes {
    bool defined = false;
    float u[3] = {0, 0, 0}, v[3] = {0, 0, 0};
  };
  Slopes slopes(std::size_t c) const;

  const VoxelGrid& grid() const { return grid_; }

  // Lattice step used for camera c; 1 means exact projection of every voxel.
  int step(std::size_t c) const { return cams_[c].step; }
  // Largest interpolation error found at the cell centres, pixels (0 for exact projection).
  double max_error(std::size_t c) const { return cams_[c].max_error; }

 private:
  struct Lattice {
    const calibration::CameraModel* model = nullptr;
    int step = 1;
    int nodes_x = 0, nodes_y = 0, nodes_z = 0;
    std::vector<float> u, v;  // nodes_x fastest
    double max_error = 0.0;
  };
  Lattice build(const calibration::CameraModel& model, int step, int threads) const;
  double measure_error(const Lattice& lattice, int threads) const;

  VoxelGrid grid_;
  std::vector<Lattice> cams_;
};

}  // namespace tomorig::recon::detail
