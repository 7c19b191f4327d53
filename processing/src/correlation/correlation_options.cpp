#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/correlation/correlation_options.h"

namespace tomorig::piv {
namespace {

void check_axis(const char* axis, int window, int downsample, int grid_size, std::size_t pass) {
  if (window < 4)
    throw bad_input(fmt::format("correlation: passes[{}].window.{} = {}; it must be >= 4 voxels", pass, axis, window));
  if (window % downsample != 0)
    throw bad_input(fmt::format("correlation: passes[{}].window.{} = {} is not a multiple of downsample = {}; "
                                "choose a window divisible by the binning factor",
                                pass, axis, window, downsample));
  if (window / downsample < 4)
    throw bad_input(fmt::format("correlation: passes[{}].window.{} = {} leaves {} voxels after downsample = {}; "
                                "use a larger window or a smaller downsample",
                                pass, axis, window, window / downsample, downsample));
  if (window > grid_size || window / downsample > grid_size / downsample)
    throw bad_input(fmt::format("correlation: passes[{}].window.{} = {} is larger than the volume ({} voxels along {}); "
                                "use a smaller interrogation volume",
                                pass, axis, window, grid_size, axis));
}

}  // namespace

void CorrelationOptions::validate(const VoxelGrid& grid) const {
  if (passes.empty()) throw bad_input("correlation: passes is empty; give at least one correlation pass");
  if (grid.nx <= 0 || grid.ny <= 0 || grid.nz <= 0)
    throw bad_input(fmt::format("correlation: volume grid is {} x {} x {}; it must hold voxels", grid.nx, grid.ny, grid.nz));
  for (std::size_t p = 0; p < passes.size(); ++p) {
    const CorrelationPass& pass = passes[p];
    if (pass.downsample != 1 && pass.downsample != 2 && pass.downsample != 4)
      throw bad_input(fmt::format("correlation: passes[{}].downsample = {}; it must be 1, 2 or 4", p, pass.downsample));
    if (!(pass.overlap >= 0.0 && pass.overlap <= 0.875))
      throw bad_input(fmt::format("correlation: passes[{}].overlap = {}; it must lie in [0, 0.875] (the thesis uses 0.5-0.75)",
                                  p, pass.overlap));
    check_axis("x", pass.window.x, pass.downsample, grid.nx, p);
    check_axis("y", pass.window.y, pass.downsample, grid.ny, p);
    check_axis("z", pass.window.z, pass.downsample, grid.nz, p);
  }
  if (!(gaussian_sigma > 0.0 && gaussian_sigma <= 2.0))
    throw bad_input(fmt::format("correlation: gaussian_sigma = {}; it must lie in (0, 2] (a fraction of the window edge)",
                                gaussian_sigma));
  if (!(min_peak >= 0.0 && min_peak < 1.0))
    throw bad_input(fmt::format("correlation: min_peak = {}; it must lie in [0, 1)", min_peak));
  if (!(max_displacement >= 0.0) || !std::isfinite(max_displacement))
    throw bad_input(fmt::format("correlation: max_displacement = {}; it must be >= 0 voxel (0 disables)", max_displacement));
  if (!(median_test.epsilon > 0.0) || !std::isfinite(median_test.epsilon))
    throw bad_input(fmt::format("correlation: median_test.epsilon = {}; it must be > 0 voxel", median_test.epsilon));
  if (!(median_test.threshold > 0.0) || !std::isfinite(median_test.threshold))
    throw bad_input(fmt::format("correlation: median_test.threshold = {}; it must be > 0", median_test.threshold));
  if (!(min_illumination >= 0.0 && min_illumination <= 1.0))
    throw bad_input(fmt::format("correlation: min_illumination = {}; it must lie in [0, 1]", min_illumination));
  if (threads < 0) throw bad_input(fmt::format("correlation: threads = {}; it must be >= 0 (0: OpenMP default)", threads));
}

CorrelationOptions CorrelationOptions::multigrid(WindowSize final_window, double overlap, int deformation_passes,
                                                 Interpolation interpolation) {
  CorrelationOptions options;
  CorrelationPass coarse;
  coarse.window = {final_window.x * 2, final_window.y * 2, final_window.z * 2};
  coarse.overlap = 0.5;
  coarse.downsample = 2;
  options.passes.push_back(coarse);
  CorrelationPass offset;
  offset.window = final_window;
  // When deformation passes follow, the integer-offset pass only feeds them, at most at 50 %
  // overlap: its vectors carry the gradient bias of undeformed windows, and at 75 % that
  // error varies from node to node on scales finer than a window, which no later window can
  // correct (reduced tpiv-thesis truth volumes: 0.097 voxel against 0.067 with 50 %; and 8x
  // fewer windows to correlate).
  offset.overlap = deformation_passes > 0 ? std::min(overlap, 0.5) : overlap;
  options.passes.push_back(offset);
  offset.overlap = overlap;
  for (int n = 0; n < deformation_passes; ++n) {
    CorrelationPass deform = offset;
    deform.deformation = true;
    deform.interpolation = interpolation;
    options.passes.push_back(deform);
  }
  return options;
}

}  // namespace tomorig::piv
