#include "pair_processor.h"

#include <tuple>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/pipeline/correlation_args.h"
#include "tomorig/pipeline/exposure_images.h"
#include "tomorig/pipeline/report_json.h"
#include "tomorig/processing/reconstruction/smoothing.h"

namespace tomorig::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

nlohmann::json grid_json(const VoxelGrid& g) {
  return {{"nx", g.nx}, {"ny", g.ny}, {"nz", g.nz}, {"voxel_mm", g.voxel_size}, {"origin_mm", {g.origin.x, g.origin.y, g.origin.z}}};
}

ReconstructionSetup setup_for(const SessionDescription& recording, const SessionCameras& cameras,
                              const BackendOptions& options) {
  ReconstructionChoices choices = options.reconstruction;
  choices.options.threads = options.threads;
  return reconstruction_setup(recording, cameras, choices);
}

piv::CorrelationOptions correlation_for(const BackendOptions& options, const VoxelGrid& grid) {
  CorrelationArgs args = options.correlation;
  args.threads = options.threads;
  const piv::CorrelationOptions corr = correlation_options(args);
  // The multigrid starts at twice --window on volumes binned 2x: a window more than half the grid
  // is refused here in the user's own terms, not as the doubled first pass (issue 23).
  const piv::WindowSize w = parse_window(args.window);
  for (const auto& [axis, size, voxels] : {std::tuple{'x', w.x, grid.nx}, std::tuple{'y', w.y, grid.ny},
                                           std::tuple{'z', w.z, grid.nz}})
    if (2 * size > voxels)
      throw bad_input(fmt::format("--window {}: {} = {} is larger than the volume allows ({} voxels along {}; the "
                                  "multigrid's first pass is twice the window, {} voxels); use at most {} along {}",
                                  args.window, axis, size, voxels, axis, 2 * size, voxels / 2, axis));
  corr.validate(grid);  // an interrogation volume larger than the grid fails here, before any work
  return corr;
}

}  // namespace

PairProcessor::PairProcessor(const SessionDescription& recording, const BackendOptions& options)
    : name_(recording.name),
      options_(options),
      cameras_(session_cameras(recording, options.calib)),
      setup_(setup_for(recording, cameras_, options)),
      reconstructor_(recon::make_reconstructor(setup_.options)),
      correlation_(correlation_for(options, setup_.input.grid)) {}

void PairProcessor::set_iteration_progress(std::function<void(int, int)> progress) const {
  if (!progress) {
    reconstructor_->set_iteration_observer({});
    return;
  }
  const int at_most = setup_.options.max_iterations;
  reconstructor_->set_iteration_observer(
      [progress = std::move(progress), at_most](const recon::IterationView& v) { progress(v.iteration, at_most); });
}

ReconstructedSet PairProcessor::reconstruct(const FrameSet& set, std::uint64_t index, std::int64_t dt_ns,
                                            const std::function<void(char)>& exposure_started) const {
  ReconstructedSet r;
  r.index = index;
  r.dt_ns = dt_ns;
  r.started = Clock::now();
  recon::ReconstructionInput in = setup_.input;
  for (const Exposure e : {Exposure::A, Exposure::B}) {
    in.images = exposure_images(set, e, name_, index, "process the other sets with --sets or repair the recording");
    if (exposure_started) exposure_started(e == Exposure::A ? 'A' : 'B');
    recon::ReconstructionReport report;
    SparseVolume v = reconstructor_->reconstruct(in, report);
    if (!options_.smooth.empty())
      v = recon::gaussian_smooth(v, {options_.smooth[0], options_.smooth[1], options_.smooth[2]}, options_.threads);
    r.reports[e == Exposure::A ? "a" : "b"] = to_json(report);
    (e == Exposure::A ? r.a : r.b) = std::move(v);
  }
  return r;
}

storage::SetResult PairProcessor::correlate(const ReconstructedSet& pair, piv::CorrelationReport& report) const {
  storage::SetResult result;
  result.field = piv::correlate(pair.a, pair.b, correlation_, report);
  result.set_index = pair.index;
  result.dt_ns = pair.dt_ns;
  result.report_json = nlohmann::json{{"reconstruction", pair.reports}, {"correlation", to_json(report)}}.dump();
  result.seconds = std::chrono::duration<double>(Clock::now() - pair.started).count();
  return result;
}

nlohmann::json PairProcessor::parameters() const {
  const recon::ReconstructionOptions& r = setup_.options;
  return {{"grid", grid_json(setup_.input.grid)},
          {"reconstruction", {{"algorithm", r.algorithm}, {"max_iterations", r.max_iterations},
                              {"relaxation", r.relaxation}, {"sigma_px", options_.reconstruction.sigma_px},
                              {"psf", options_.reconstruction.psf},
                              {"smoothing_sigma_voxel", options_.smooth}, {"cameras", cameras_.source}}},
          {"correlation", to_json(correlation_)}};
}

}  // namespace tomorig::pipeline
