// tomorig process: the back-end (pipeline::run_backend). For each set of a session: preprocess
// the frames, reconstruct both exposures, correlate them into a results file that is complete
// after every set, so an interrupted run resumes where it stopped.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "process_progress.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/backend.h"
#include "tomorig/rig/stop_signal.h"

namespace tomorig::app {
namespace {

struct ProcessArgs {
  std::string session;
  std::string out;
  std::string config;
  std::string png;
  bool json = false;
  pipeline::BackendOptions backend;
};

void run(const ProcessArgs& args) {
  pipeline::BackendOptions options = args.backend;
  options.out = args.out;
  options.preprocess_chain = args.config;
  options.png = args.png;
  const rig::StopSignalGuard stop_signal;
  std::unique_ptr<ProgressLine> progress;
  pipeline::BackendHooks hooks;
  hooks.should_stop = [&] { return stop_signal.stop_requested(); };
  hooks.notice = [&](const std::string& text) {
    if (progress) progress->break_line();
    // A warning of the pipeline (e.g. a poor calibration) stays visible under --quiet.
    if (text.rfind("warning: ", 0) == 0) spdlog::warn("{}", text.substr(9));
    else spdlog::info("{}", text);
  };
  hooks.started = [&](std::uint64_t sets_to_do) { progress = std::make_unique<ProgressLine>(sets_to_do); };
  hooks.set_done = [&](const pipeline::BackendSetDone& s) {
    const std::string by =
        s.rank < 0 ? std::string()
                   : fmt::format(" on rank {} (its {} sets, {:.3g} sets/s)", s.rank, s.rank_sets, s.rank_sets_per_second);
    if (progress) progress->break_line();
    spdlog::info("set {} done{}: {} vectors, {:.1f} % valid, {:.1f} s", s.index, by, s.vectors,
                 100.0 * s.valid_fraction, s.seconds);
    if (progress) progress->set_done();
  };
  pipeline::BackendReport report;
  try {
    report = pipeline::run_backend(args.session, options, hooks);
  } catch (...) {
    if (progress) progress->break_line();  // the error on a line of its own
    throw;
  }
  if (report.worker_rank) return;  // an MPI rank other than 0: rank 0 reports the run
  if (progress) progress->break_line();
  if (report.interrupted)
    throw runtime_error(fmt::format("interrupted by {}: '{}' is valid and holds {} of {} sets; run the same command "
                                    "again to resume",
                                    stop_signal.signal_name(), args.out, report.sets_in_file, report.sets_asked));
  if (args.json)
    fmt::print("{}\n", report.to_json().dump(2));
  else
    fmt::print("{}\n", report.brief());
}

}  // namespace

void add_process_command(CLI::App& root) {
  auto args = std::make_shared<ProcessArgs>();
  pipeline::BackendOptions& b = args->backend;
  pipeline::ReconstructionChoices& r = b.reconstruction;
  CLI::App* cmd = root.add_subcommand(
      "process", "Back-end: preprocess, reconstruct and correlate every set of a session into a results file");
  cmd->add_option("--session", args->session, "Session file (.h5)")->required();
  cmd->add_option("--calib", b.calib,
                  "Calibration file (TOML), or 'truth' for a simulated session's exact cameras (default: the truth "
                  "if present, else the rig config's calibration file)");
  cmd->add_option("--config", args->config,
                  "Preprocessing chain ([[preprocess.steps]] TOML, as for 'tomorig preprocess --chain'); default: none");
  cmd->add_option("-o,--out", args->out, "Results file (.h5); an existing one of the same session and parameters is "
                                         "resumed")
      ->required();
  pipeline::add_reconstruction_flags(*cmd, r, r.options.algorithm);
  cmd->add_option("--smooth", b.smooth, "Gaussian smoothing sigma x,y,z (voxel) of each reconstructed volume")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--dt-ns", b.dt_ns, "Pulse separation in ns, for sessions that did not record it");
  cmd->add_option("--max-sets", b.max_sets, "Process only the first N sets (0: all)");
  pipeline::add_correlation_flags(*cmd, b.correlation);
  cmd->add_option("--threads", b.threads, "OpenMP threads per stage (0: all cores)")->capture_default_str();
  cmd->add_flag("--sequential", b.sequential, "Do not overlap reconstruction and correlation of different sets");
  cmd->add_flag("--overwrite", b.overwrite, "Start a new results file even if one exists");
  cmd->add_flag("--json", args->json, "Print the summary as JSON");
  cmd->add_option("--png", args->png,
                  "Also write a picture (PNG) of the mean field's middle z-slice: grey = in-plane magnitude, line = "
                  "direction, black = no valid vector");
  cmd->footer(
      "On several processes or nodes: mpirun -n N tomorig process ... (as root add --allow-run-as-root). Rank 0 "
      "writes the results file and hands out the sets; same file, resume and exit codes (docs/correlation.md, "
      "\"Processing on a cluster\").");
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
