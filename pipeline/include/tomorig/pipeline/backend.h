#pragma once
// The back-end (thesis Ch. 3-5 as a production run): for each set of a session, preprocess the
// frames, reconstruct both exposures, correlate them; the vector fields and their ensemble
// statistics go into a results file (storage/results_file.h) that is complete after every set,
// so an interrupted run resumes where it stopped. Reconstruction of one set overlaps the
// correlation of the previous one when memory allows.
//
//   pipeline::BackendOptions options;  options.out = "results.h5";
//   const pipeline::BackendReport report = pipeline::run_backend("session.h5", options);
//   fmt::print("{}\n", report.brief());
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/geometry.h"
#include "tomorig/pipeline/correlation_args.h"
#include "tomorig/pipeline/session_geometry.h"

namespace tomorig::pipeline {

struct BackendOptions {
  std::filesystem::path out;  // the results file; an existing one of the same session is resumed
  // Cameras: "truth" (a simulated session's exact cameras), a calibration file, or empty: the
  // truth if present, else the rig config's calibration file.
  std::string calib;
  // Preprocessing chain ([[preprocess.steps]] TOML, docs/preprocessing.md); empty: none.
  std::filesystem::path preprocess_chain;
  // The rig config's processing.algorithm is deliberately not used: the back-end reconstructs
  // with FMART unless `algorithm` says otherwise (issue 5).
  ReconstructionChoices reconstruction{.algorithm_from_rig = false};
  std::vector<double> smooth;  // Gaussian smoothing sigma x,y,z (voxel) of each volume; empty: none
  CorrelationArgs correlation;
  std::int64_t dt_ns = 0;      // pulse separation for sessions that did not record it; 0: the session's
  std::uint64_t max_sets = 0;  // process only the first N sets; 0: all
  int threads = 0;             // OpenMP threads per stage; 0: all cores
  bool overwrite = false;      // start a new results file even if one exists
  bool sequential = false;     // never overlap reconstruction and correlation
  std::filesystem::path png;   // also draw the mean field's middle z-slice here; empty: no picture

  // Throws tomorig::Error (bad_input) naming the option.
  void validate() const;
};

// One set finished (for progress lines).
struct BackendSetDone {
  std::uint64_t index = 0;
  std::size_t vectors = 0;
  double valid_fraction = 0.0;
  double seconds = 0.0;  // from reading the set to its result written
  // Under MPI: the rank that did the set, how many it has done and its sets/s since the start;
  // rank -1 in a single process.
  int rank = -1;
  std::uint64_t rank_sets = 0;
  double rank_sets_per_second = 0.0;
};

// One MPI rank's share of a run (BackendReport::ranks).
struct BackendRankFigures {
  int rank = 0;
  std::string host;
  long pid = 0;
  int threads = 0;                // OpenMP threads per stage on that rank
  std::uint64_t sets = 0;         // sets it finished in this run
  double busy_seconds = 0.0;      // the sum of its sets' times (read to result; overlapped sets both count)
};

// The work in hand inside a set (a set can take minutes), for progress within a set.
struct BackendStep {
  enum class Kind { preprocessing, reconstructing, correlating };
  std::uint64_t set = 0;
  Kind kind = Kind::preprocessing;
  char exposure = 'A';  // reconstructing: 'A' or 'B'
  int iteration = 0;    // reconstructing with SMART/FMART: iterations done of `iterations`; else 0
  int iterations = 0;
  // "set 3: reconstructing B, iteration 4/7", "set 3: correlating"
  std::string text() const;
};

struct BackendHooks {
  // Asked between sets; true stops after the set in hand, leaving a valid, resumable file.
  std::function<bool()> should_stop;
  // Messages for the operator: resuming, what is about to be processed.
  std::function<void(const std::string&)> notice;
  // The work is about to start: this many sets to do (the resumed ones left out).
  std::function<void(std::uint64_t sets_to_do)> started;
  std::function<void(const BackendSetDone&)> set_done;
  // A step inside a set started (and each reconstruction iteration). With reconstruction and
  // correlation overlapped it is called from two threads (one set reconstructing, the previous
  // one correlating). Not called under MPI.
  std::function<void(const BackendStep&)> step;
};

// Where a run's time went: each stage's wall seconds summed over the sets processed. With
// reconstruction and correlation overlapped the stages of different sets run at the same time,
// so the sum can exceed the run's seconds; --sequential separates them.
struct BackendStageSeconds {
  double load = 0.0;            // reading the set's frames from the session
  double preprocess = 0.0;      // the preprocessing chain (0 without --chain)
  double reconstruction = 0.0;  // both exposures (and --smooth)
  double correlation = 0.0;     // the vector field and the set's report
  double write = 0.0;           // adding the set to the results file

  BackendStageSeconds& operator+=(const BackendStageSeconds& o);
};

struct BackendReport {
  std::filesystem::path out, xdmf, session;
  std::uint64_t sets_asked = 0;      // sets of the session to be in the file (max_sets applied)
  std::uint64_t sets_in_file = 0;
  std::uint64_t sets_processed = 0;  // by this run
  std::uint64_t sets_resumed = 0;    // found finished in an existing file
  bool overlapped = false;           // reconstruction and correlation ran concurrently
  bool interrupted = false;          // should_stop ended the run early: the file is valid and resumable
  int nodes[3] = {0, 0, 0};
  double mean_valid_fraction = 0.0;  // over the sets processed now
  double mean_speed_m_s = 0.0;       // of the ensemble mean field, over nodes with a valid vector
  Vec3d mean_displacement_voxel;     // spatial mean of the ensemble mean displacement
  Vec3d spatial_std_displacement_voxel;
  double seconds = 0.0;
  // A single process: its stages' seconds, and the CPU time (all threads) and minor page faults
  // of the run (the machine's hidden cost, docs/performance.md "Page faults"). Not under MPI.
  BackendStageSeconds stage_seconds;
  double cpu_user_seconds = 0.0, cpu_system_seconds = 0.0;
  long minor_page_faults = 0;
  // Under MPI (on rank 0; a single process leaves them empty): every rank's share.
  std::vector<BackendRankFigures> ranks;
  // Under MPI on a rank other than 0: this rank only worked for rank 0, which reports the run;
  // nothing else in the report is filled in.
  bool worker_rank = false;

  double sets_per_second() const { return sets_processed > 0 && seconds > 0 ? sets_processed / seconds : 0.0; }
  nlohmann::json to_json() const;
  // "wrote r.h5 and r.xdmf: 4 sets (4 processed now, 0 resumed), ... ", and under MPI one more
  // line per rank: "rank 1 (pid 4711 on node7, 2 threads): 12 sets, 0.11 sets/s, 8.7 s per set".
  std::string brief() const;
  // The per-rank lines alone ("" in a single process), each starting with a newline.
  std::string ranks_brief() const;
};

// Throws tomorig::Error: bad_input for a bad option, session, calibration or a set that cannot
// be processed (a missing frame, no pulse separation), naming what to change; runtime for a
// failure of the results file.
//
// Started by mpirun (or srun), the run is one of an MPI job's ranks (cluster_backend.cpp): rank
// 0 owns the results file and hands out the sets one at a time to whichever rank asks next,
// itself included; the hooks are called on rank 0 only, and the other ranks return a report with
// worker_rank set. Without a launcher MPI is never initialised.
BackendReport run_backend(const std::filesystem::path& session, const BackendOptions& options,
                          const BackendHooks& hooks = {});

}  // namespace tomorig::pipeline
