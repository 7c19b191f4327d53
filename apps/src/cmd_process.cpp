// tomorig process: the back-end (pipeline::run_backend). For each set of a session: preprocess
// the frames, reconstruct both exposures, correlate them into a results file that is complete
// after every set, so an interrupted run resumes where it stopped.
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "json_summary.h"
#include "process_progress.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/console.h"
#include "tomorig/core/error.h"
#include "tomorig/core/set_selection.h"
#include "tomorig/pipeline/backend.h"
#include "tomorig/rig/stop_signal.h"

namespace tomorig::app {
namespace {

struct ProcessArgs {
  std::string session;
  std::string out;
  std::string chain;
  std::string png;
  std::string sets;  // the one set syntax; process takes the first N sets
  std::optional<double> dt_ns;
  JsonOutput json;
  pipeline::BackendOptions backend;
};

void run(const ProcessArgs& args) {
  cli::require_session(args.session, "process");
  pipeline::BackendOptions options = args.backend;
  options.out = args.out;
  options.preprocess_chain = args.chain;
  if (!args.sets.empty())
    options.max_sets = SetSelection::parse(args.sets).leading_count(
        "a results file holds the sets of a session from set 0 on, in order (resume continues there)");
  if (args.dt_ns) options.dt_ns = static_cast<std::int64_t>(std::llround(*args.dt_ns));
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
  hooks.step = [&](const pipeline::BackendStep& step) {
    if (!progress) return;
    const std::string text = step.text();
    if (step.iteration == 0 && verbosity() == Verbosity::verbose) {
      progress->break_line();
      spdlog::debug("{}", text);
    }
    progress->step(text, step.kind != pipeline::BackendStep::Kind::correlating);
  };
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
  if (!args.json.to_stdout()) fmt::print("{}\n", report.brief());
  nlohmann::json summary = json_summary("process");
  summary.update(report.to_json());
  emit_json(args.json, summary);
}

}  // namespace

void add_process_command(CLI::App& root) {
  auto args = std::make_shared<ProcessArgs>();
  pipeline::BackendOptions& b = args->backend;
  pipeline::ReconstructionChoices& r = b.reconstruction;
  CLI::App* cmd = root.add_subcommand(
      "process", "Back-end: preprocess, reconstruct and correlate every set of a session into a results file");
  cli::add_session_argument(*cmd, args->session, "Session file (.h5)");
  cmd->add_option("--calib", b.calib,
                  "Calibration file (TOML), or 'truth' for a simulated session's exact cameras (default: the truth "
                  "if present, else the rig config's calibration file)");
  cmd->add_option("--chain", args->chain,
                  "Preprocessing chain ([[preprocess.steps]] TOML, as for 'tomorig preprocess --chain') or a preset: "
                  "shadow-a, shadow-b (thesis Sect. 7.4); default: none");
  cli::add_deprecated_option(*cmd, "--config", args->chain, "--chain (--config names the rig file elsewhere)");
  cmd->add_option("-o,--out", args->out, "Results file (.h5); an existing one of the same session and parameters is "
                                         "resumed")
      ->required();
  pipeline::add_reconstruction_flags(*cmd, r, r.options.algorithm);
  cmd->add_option("--smooth", b.smooth, "Gaussian smoothing sigma x,y,z (voxel) of each reconstructed volume")
      ->delimiter(',')
      ->expected(3);
  cli::add_dt_option(*cmd, args->dt_ns, "Pulse separation, for sessions that did not record it");
  cmd->add_option("--sets", args->sets, "Sets to process: N (the first N) or 0:N; default all");
  cmd->add_option_function<std::uint64_t>(
         "--max-sets",
         [args](std::uint64_t n) {
           cli::warn_deprecated("--max-sets", "--sets N");
           if (n > 0) args->sets = std::to_string(n);
         },
         "deprecated: use --sets N")
      ->group("");
  pipeline::add_correlation_flags(*cmd, b.correlation);
  cmd->add_option("--threads", b.threads, "OpenMP threads per stage (0: all cores)")->capture_default_str();
  cmd->add_flag("--sequential", b.sequential, "Do not overlap reconstruction and correlation of different sets");
  cmd->add_flag("--overwrite", b.overwrite, "Start a new results file even if one exists");
  add_json_flag(*cmd, args->json);
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
