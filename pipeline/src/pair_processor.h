#pragma once
// The work of the back-end on one set, shared by run_backend (a session, resumable, stages
// overlapped) and the backend stage (sets as they come): reconstruct both exposures, then
// correlate them into a result for the results file.
#include <chrono>
#include <functional>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/core/volume.h"
#include "tomorig/pipeline/backend.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/processing/correlation/correlate.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::pipeline {

// The reconstructed pair of one set, passed from reconstruction to correlation.
struct ReconstructedSet {
  std::uint64_t index = 0;
  std::int64_t dt_ns = 0;
  SparseVolume a, b;
  nlohmann::json reports;
  std::chrono::steady_clock::time_point started;
};

class PairProcessor {
 public:
  // Cameras, grid, reconstruction and correlation options from `recording` and `options`;
  // bad_input naming the option for anything wrong, before any set is touched.
  PairProcessor(const SessionDescription& recording, const BackendOptions& options);

  // `set` already preprocessed. bad_input naming the set and camera if a frame is missing.
  // `exposure_started` ('A', 'B') is told before each exposure's reconstruction.
  ReconstructedSet reconstruct(const FrameSet& set, std::uint64_t index, std::int64_t dt_ns,
                               const std::function<void(char)>& exposure_started = {}) const;
  // Told after every SMART/FMART iteration (iterations done, iterations at most); one
  // reconstruction at a time.
  void set_iteration_progress(std::function<void(int done, int at_most)> progress) const;
  // Correlates the pair into a result (field, reports, timing) for ResultsWriter::add.
  storage::SetResult correlate(const ReconstructedSet& pair, piv::CorrelationReport& report) const;

  // What the results file records of this run (grid, reconstruction, correlation).
  nlohmann::json parameters() const;
  const recon::ReconstructionInput& input() const { return setup_.input; }
  const recon::ReconstructionOptions& reconstruction() const { return setup_.options; }
  const SessionCameras& cameras() const { return cameras_; }

 private:
  std::string name_;
  BackendOptions options_;
  SessionCameras cameras_;
  ReconstructionSetup setup_;
  std::unique_ptr<recon::Reconstructor> reconstructor_;
  piv::CorrelationOptions correlation_;
};

}  // namespace tomorig::pipeline
