#pragma once
// The sums of the sparse direct correlation (direct_correlator.h) for every window of a
// deformation pass at once, by separable contraction (thesis Sect. 2.5: sums shared between
// overlapping windows). The window weights are a product of per-axis weights, so a window's
// sum over its voxels of (per-voxel value) x (weight product) is a sum over x of sums over y of
// sums over z: each occupied voxel is visited once per pass (not once per window containing it,
// 64 times at 75 % overlap), its 27 lag products A(x) B(x + s) computed once, and the
// per-window sums are built row by row, then plane by plane, in float lanes without gathers.
//
// What the contraction computes, per window (lags s in -1..1 per axis, index lag_index):
//  - P(s) over the (voxel, lag) pairs whose lag stays inside the window, where the circular
//    lag of the FFT's correlation equals the plain one; the caller adds the pairs of the
//    window's shell whose lag wraps around it;
//  - QA(s) = sum w(x) A(x) w(x (+) s) and QB(s) = sum w(y) B(y) w(y (-) s), circular (only the
//    weights wrap, so the whole window separates);
//  - sum A, sum w^2 A, sum w^2 A^2 and the same of B (means and energies).
// A and B count where listed by list_occupied; the B of the lag products is read dense.
#include <cstdint>
#include <vector>

#include "correlation/direct_correlator.h"
#include "correlation/volume_view.h"

namespace tomorig::piv::detail {

// Slots of one window's sums (floats, kLagSlots per window).
inline constexpr int kLagSlots = 96;
inline constexpr int kSlotP = 0, kSlotQA = 27, kSlotSumA = 54, kSlotW2A = 55, kSlotW2A2 = 56;
inline constexpr int kSlotQB = 64, kSlotSumB = 91, kSlotW2B = 92, kSlotW2B2 = 93;

struct WindowLagSums {
  Int3 nodes;
  std::vector<float> sums;  // node n's slots at n * kLagSlots (node order x fastest)
  // Scratch kept between passes and sets, per thread: one z plane's row sums of a slab of
  // windows along x, [window x][y][slot], and whether a row sum is non-zero.
  std::vector<std::vector<float>> rows;
  std::vector<std::vector<std::uint8_t>> row_used;
};

// Windows of `window` voxels at node * `step` (all inside the volumes), `nodes` per axis;
// oa/ob the occupied voxels of a and b (their rows), b the dense volume read at the lags;
// wx/wy/wz the per-axis weights (the FFT path's).
void window_lag_sums(const OccupiedVoxels& oa, const VolumeView& b, const OccupiedVoxels& ob, Int3 window,
                     Int3 step, Int3 nodes, const std::vector<float>& wx, const std::vector<float>& wy,
                     const std::vector<float>& wz, int threads, WindowLagSums& out);

}  // namespace tomorig::piv::detail
