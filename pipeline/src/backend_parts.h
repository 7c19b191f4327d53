#pragma once
// The steps of a back-end run shared by one process (backend.cpp) and an MPI job
// (cluster_backend.cpp): what every rank needs to process sets, and what the owner of the
// results file does before and after.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <functional>
#include <optional>
#include <vector>

#include "pair_processor.h"
#include "tomorig/pipeline/backend.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {

// The session, the set-up of reconstruction and correlation (the rig config parsed once) and the
// pulse separation of every set to process; bad_input for anything wrong, before any set is read.
class BackendInputs {
 public:
  BackendInputs(const std::filesystem::path& session_path, const BackendOptions& options);

  // The preprocessing chain's sequence statistics take passes over the whole session, so they are
  // made after the quick checks (the results file's) have passed.
  void prepare_preprocessing();
  // Reads set `index`, preprocesses it and reconstructs both exposures; its time starts here.
  // `step` (may be empty) is told of preprocessing and of each exposure's reconstruction.
  ReconstructedSet reconstruct(std::uint64_t index, const std::function<void(const BackendStep&)>& step = {});

  const std::filesystem::path path;
  const BackendOptions options;
  const storage::SessionReader session;
  const PairProcessor processor;
  const std::uint64_t sets_asked;  // max_sets applied
  const std::vector<std::int64_t> dt;
  // Load, preprocess and reconstruction seconds of the sets reconstructed so far (by the thread
  // that calls reconstruct()).
  BackendStageSeconds stage_seconds;

 private:
  std::optional<SessionPreprocessor> preprocessor_;
};

// The results file of this run, new or resumed (bad_input if it belongs to another session, grid
// or parameters); created at once so that the path is known to work.
std::unique_ptr<storage::ResultsWriter> open_results(const BackendInputs& inputs);
// The sets of 0 .. sets_asked - 1 that the file does not hold yet, ascending.
std::vector<std::uint64_t> sets_to_do(const storage::ResultsWriter& writer, std::uint64_t sets_asked);
// The report's fields known before processing.
BackendReport start_report(const BackendInputs& inputs, const storage::ResultsWriter& writer);
// Closes the file (its errors surface here), then the summary figures and the picture (--png).
void finish_results(storage::ResultsWriter& writer, const BackendOptions& options, BackendReport& report);

}  // namespace tomorig::pipeline
