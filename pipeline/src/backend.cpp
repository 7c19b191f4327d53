#include "tomorig/pipeline/backend.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/core.h>
#include <sys/resource.h>

#include "backend_parts.h"
#include "cluster_backend.h"
#include "memory_policy.h"
#include "mpi_world.h"
#include "session_identity.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "tomorig/pipeline/slice_png.h"
#include "tomorig/pipeline/two_stage_pipeline.h"
#include "tomorig/processing/preprocess/chain_spec.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// CPU time (user, system) of the whole process and its minor page faults so far.
struct ProcessUsage {
  double user = 0.0, system = 0.0;
  long minor_faults = 0;
};
ProcessUsage process_usage() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return {seconds(u.ru_utime), seconds(u.ru_stime), u.ru_minflt};
}

// The results file must match this run: same session first (the clearer message), then the grid.
void check_existing_results(const fs::path& out, const std::string& identity, const nlohmann::json& grid) {
  const storage::ResultsReader existing(out);
  if (existing.info().session_identity != identity) return;  // the writer says "another session"
  const nlohmann::json old = nlohmann::json::parse(existing.info().parameters_json, nullptr, false);
  if (old.is_object() && old.contains("grid") && old["grid"] != grid)
    throw bad_input(fmt::format("results file '{}' was made on another reconstruction grid ({}) than this run's ({}); "
                                "its sets cannot be combined: choose another --out, the same --grid, or --overwrite",
                                out.string(), old["grid"].dump(), grid.dump()));
}

// The pulse separation of every set to process; a missing one is found before hours of work.
std::vector<std::int64_t> pulse_separations(const storage::SessionReader& session, const fs::path& path,
                                            const BackendOptions& options, std::uint64_t set_total) {
  std::vector<std::int64_t> dt(set_total);
  for (std::uint64_t s = 0; s < set_total; ++s) {
    dt[s] = options.dt_ns > 0 ? options.dt_ns : session.set_record(s).dt_ns;
    if (dt[s] <= 0)
      throw bad_input(fmt::format("set {} of session '{}' has pulse separation dt = {} ns (missing), so its velocity "
                                  "cannot be computed; give the laser pulse separation with --dt (e.g. --dt 80us)",
                                  s, path.string(), dt[s]));
  }
  return dt;
}

// The ensemble mean field's summary figures, over the nodes with a valid vector.
void summarise(const storage::EnsembleStatistics& stats, BackendReport& report) {
  double speed = 0.0;
  std::size_t nodes = 0;
  Vec3d sum, sum2;  // of the mean displacement over the nodes: its spatial mean and spread
  for (std::size_t i = 0; i < stats.mean_velocity.size(); ++i)
    if (stats.valid_count[i] > 0) {
      const Vec3d& u = stats.mean_velocity[i];
      speed += std::sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
      const Vec3d& d = stats.mean_displacement_voxel[i];
      sum = sum + d;
      sum2 = sum2 + Vec3d{d.x * d.x, d.y * d.y, d.z * d.z};
      ++nodes;
    }
  const double inv = nodes > 0 ? 1.0 / nodes : 0.0;
  const Vec3d mean_d = sum * inv;
  report.nodes[0] = stats.nx;
  report.nodes[1] = stats.ny;
  report.nodes[2] = stats.nz;
  report.mean_speed_m_s = speed * inv;
  report.mean_displacement_voxel = mean_d;
  report.spatial_std_displacement_voxel = {std::sqrt(std::max(0.0, sum2.x * inv - mean_d.x * mean_d.x)),
                                           std::sqrt(std::max(0.0, sum2.y * inv - mean_d.y * mean_d.y)),
                                           std::sqrt(std::max(0.0, sum2.z * inv - mean_d.z * mean_d.z))};
}

void draw_mean_slice(const storage::EnsembleStatistics& stats, const fs::path& png) {
  std::vector<bool> counted(stats.valid_count.size());
  for (std::size_t i = 0; i < counted.size(); ++i) counted[i] = stats.valid_count[i] > 0;
  write_slice_png(png, stats.nx, stats.ny, stats.nz, stats.nz / 2, stats.mean_displacement_voxel, counted, stats.origin,
                  stats.spacing);
}

}  // namespace

void BackendOptions::validate() const {
  if (out.empty()) throw bad_input("the back-end has no results file: give one with -o/--out");
  if (dt_ns < 0) throw bad_input(fmt::format("--dt {}ns must be > 0", dt_ns));
  if (!smooth.empty() && smooth.size() != 3)
    throw bad_input(fmt::format("--smooth takes 3 sigmas x,y,z (voxel), not {}", smooth.size()));
}

std::string BackendStep::text() const {
  switch (kind) {
    case Kind::preprocessing:
      return fmt::format("set {}: reading and preprocessing", set);
    case Kind::reconstructing:
      return iterations > 0 ? fmt::format("set {}: reconstructing {}, iteration {}/{}", set, exposure, iteration, iterations)
                            : fmt::format("set {}: reconstructing {}", set, exposure);
    case Kind::correlating:
      return fmt::format("set {}: correlating", set);
  }
  return {};
}

BackendStageSeconds& BackendStageSeconds::operator+=(const BackendStageSeconds& o) {
  load += o.load;
  preprocess += o.preprocess;
  reconstruction += o.reconstruction;
  correlation += o.correlation;
  write += o.write;
  return *this;
}

nlohmann::json BackendReport::to_json() const {
  const Vec3d& m = mean_displacement_voxel;
  const Vec3d& s = spatial_std_displacement_voxel;
  nlohmann::json json = {{"out", out.string()},
          {"xdmf", xdmf.string()},
          {"session", session.string()},
          {"sets_in_file", sets_in_file},
          {"sets_processed", sets_processed},
          {"sets_resumed", sets_resumed},
          {"nodes", {nodes[0], nodes[1], nodes[2]}},
          {"mean_valid_fraction", mean_valid_fraction},
          {"mean_speed_m_s", mean_speed_m_s},
          {"mean_displacement_voxel", {m.x, m.y, m.z}},
          {"spatial_std_displacement_voxel", {s.x, s.y, s.z}},
          {"seconds", seconds},
          {"sets_per_second", sets_per_second()}};
  if (!ranks.empty()) {
    nlohmann::json list = nlohmann::json::array();
    for (const BackendRankFigures& r : ranks)
      list.push_back({{"rank", r.rank},
                      {"host", r.host},
                      {"pid", r.pid},
                      {"threads", r.threads},
                      {"sets", r.sets},
                      {"busy_seconds", r.busy_seconds},
                      {"sets_per_second", seconds > 0 ? r.sets / seconds : 0.0}});
    json["mpi_ranks"] = list;
  } else {
    const BackendStageSeconds& t = stage_seconds;
    json["stage_seconds"] = {{"load", t.load}, {"preprocess", t.preprocess}, {"reconstruction", t.reconstruction},
                             {"correlation", t.correlation}, {"write", t.write}};
    json["cpu_seconds"] = cpu_user_seconds + cpu_system_seconds;
    json["cpu_user_seconds"] = cpu_user_seconds;
    json["cpu_system_seconds"] = cpu_system_seconds;
    json["minor_page_faults"] = minor_page_faults;
  }
  return json;
}

std::string BackendReport::brief() const {
  return fmt::format("wrote {} and {}: {} sets ({} processed now, {} resumed), {} x {} x {} vectors, {:.1f} % valid, "
                     "mean speed {:.4g} m/s, {:.1f} s ({:.3g} sets/s)",
                     out.string(), xdmf.string(), sets_in_file, sets_processed, sets_resumed, nodes[0], nodes[1],
                     nodes[2], 100.0 * mean_valid_fraction, mean_speed_m_s, seconds, sets_per_second()) +
         ranks_brief();
}

std::string BackendReport::ranks_brief() const {
  std::string text;
  for (const BackendRankFigures& r : ranks)
    text += fmt::format("\nrank {} (pid {} on {}, {} threads): {} sets, {:.3g} sets/s, {:.3g} s per set", r.rank, r.pid,
                        r.host, r.threads, r.sets, seconds > 0 ? r.sets / seconds : 0.0,
                        r.sets > 0 ? r.busy_seconds / r.sets : 0.0);
  return text;
}

BackendInputs::BackendInputs(const fs::path& session_path, const BackendOptions& opts)
    : path(session_path),
      options(opts),
      session(session_path),
      processor(describe_session(session), options),
      sets_asked(options.max_sets > 0 ? std::min<std::uint64_t>(options.max_sets, session.set_count())
                                      : session.set_count()),
      dt(pulse_separations(session, session_path, options, sets_asked)) {}

void BackendInputs::prepare_preprocessing() {
  if (!preprocessor_) preprocessor_.emplace(session, options.preprocess_chain);
}

ReconstructedSet BackendInputs::reconstruct(std::uint64_t index, const std::function<void(const BackendStep&)>& step) {
  prepare_preprocessing();
  const auto set_started = Clock::now();
  if (step) step({.set = index, .kind = BackendStep::Kind::preprocessing});
  FrameSet set = session.read_set(index);
  const auto loaded = Clock::now();
  preprocessor_->apply(set);
  const auto preprocessed = Clock::now();
  stage_seconds.load += seconds_between(set_started, loaded);
  stage_seconds.preprocess += seconds_between(loaded, preprocessed);
  std::function<void(char)> exposure_started;
  if (step)
    exposure_started = [&](char e) {
      step({.set = index, .kind = BackendStep::Kind::reconstructing, .exposure = e});
      processor.set_iteration_progress([&step, index, e](int done, int at_most) {
        if (done > 0)
          step({.set = index, .kind = BackendStep::Kind::reconstructing, .exposure = e, .iteration = done,
                .iterations = at_most});
      });
    };
  ReconstructedSet pair = processor.reconstruct(set, index, dt[index], exposure_started);
  if (step) processor.set_iteration_progress({});
  stage_seconds.reconstruction += seconds_between(preprocessed, Clock::now());
  pair.started = set_started;  // a set's time includes reading and preprocessing it
  return pair;
}

std::unique_ptr<storage::ResultsWriter> open_results(const BackendInputs& inputs) {
  const BackendOptions& options = inputs.options;
  const std::string identity = session_identity(inputs.session);
  nlohmann::json parameters = inputs.processor.parameters();
  parameters["preprocess"] = {{"chain_file", options.preprocess_chain.string()},
                              {"chain_toml", preprocess::chain_text(options.preprocess_chain.string())}};
  parameters["dt_override_ns"] = options.dt_ns;
  std::error_code ec;
  if (!options.overwrite && fs::exists(options.out, ec)) check_existing_results(options.out, identity, parameters["grid"]);
  auto writer = std::make_unique<storage::ResultsWriter>(
      options.out,
      storage::ResultsInfo{.session_path = inputs.path.string(),
                           .session_identity = identity,
                           .parameters_json = parameters.dump(),
                           .voxel_size_mm = inputs.processor.input().grid.voxel_size},
      storage::ResultsWriterOptions{.overwrite = options.overwrite});
  if (writer->resumed_sets() == 0) writer->write();  // an empty, valid file from the start: the path works
  return writer;
}

std::vector<std::uint64_t> sets_to_do(const storage::ResultsWriter& writer, std::uint64_t sets_asked) {
  std::vector<std::uint64_t> todo;
  for (std::uint64_t s = 0; s < sets_asked; ++s)
    if (!writer.has_set(s)) todo.push_back(s);
  return todo;
}

BackendReport start_report(const BackendInputs& inputs, const storage::ResultsWriter& writer) {
  BackendReport report;
  report.out = inputs.options.out;
  report.xdmf = storage::ResultsWriter::sidecar_path(inputs.options.out);
  report.session = inputs.path;
  report.sets_asked = inputs.sets_asked;
  report.sets_resumed = writer.resumed_sets();
  return report;
}

void finish_results(storage::ResultsWriter& writer, const BackendOptions& options, BackendReport& report) {
  writer.close();  // errors surface here rather than in the destructor
  report.sets_in_file = writer.set_count();
  const storage::EnsembleStatistics stats = writer.statistics();
  summarise(stats, report);
  if (!options.png.empty()) draw_mean_slice(stats, options.png);
}

BackendReport run_backend(const fs::path& session_path, const BackendOptions& options, const BackendHooks& hooks) {
  // Under MPI the options are checked inside the ranks' agreement, so that rank 0 alone reports them.
  if (mpi::launched_by_mpi() && (mpi::built_with_mpi() || mpi::launched_size() > 1))
    return run_backend_on_mpi(session_path, options, hooks);
  options.validate();
  const auto started = Clock::now();
  const ProcessUsage usage_at_start = process_usage();
  const auto notice = [&](const std::string& text) {
    if (hooks.notice) hooks.notice(text);
  };
  const auto stop_requested = [&] { return hooks.should_stop && hooks.should_stop(); };

  BackendInputs inputs(session_path, options);
  const recon::ReconstructionInput& input = inputs.processor.input();
  const std::unique_ptr<storage::ResultsWriter> writer = open_results(inputs);
  storage::ResultsWriter& results = *writer;
  BackendReport report = start_report(inputs, results);
  const std::vector<std::uint64_t> todo = sets_to_do(results, report.sets_asked);
  if (results.resumed_sets() > 0)
    notice(fmt::format("resuming {}: {} sets already finished, {} to do", options.out.string(), results.resumed_sets(),
                       todo.size()));

  inputs.prepare_preprocessing();
  report.overlapped = !options.sequential && overlap_fits(input.grid, available_memory_bytes());
  notice(fmt::format("processing {} sets of {} with {} on a {} x {} x {} grid ({}), {} cameras, {}", todo.size(),
                     session_path.string(), inputs.processor.reconstruction().algorithm, input.grid.nx, input.grid.ny,
                     input.grid.nz, inputs.processor.cameras().source, input.cameras.size(),
                     report.overlapped ? "reconstruction and correlation overlapped" : "one set at a time"));
  for (const std::string& warning : inputs.processor.cameras().warnings) notice("warning: " + warning);
  if (hooks.started) hooks.started(todo.size());

  std::size_t next = 0;
  const auto produce = [&](const std::function<bool()>& stop) -> std::optional<ReconstructedSet> {
    if (next >= todo.size() || stop() || stop_requested()) return std::nullopt;
    return inputs.reconstruct(todo[next++], hooks.step);
  };

  double valid_sum = 0.0;
  const auto consume = [&](ReconstructedSet& r) -> bool {
    if (stop_requested()) return false;
    if (hooks.step) hooks.step({.set = r.index, .kind = BackendStep::Kind::correlating});
    piv::CorrelationReport corr_report;
    const auto correlating = Clock::now();
    const storage::SetResult result = inputs.processor.correlate(r, corr_report);
    const auto correlated = Clock::now();
    results.add(result);
    report.stage_seconds.correlation += seconds_between(correlating, correlated);
    report.stage_seconds.write += seconds_between(correlated, Clock::now());
    valid_sum += corr_report.valid_fraction();
    ++report.sets_processed;
    if (hooks.set_done)
      hooks.set_done({.index = r.index,
                      .vectors = corr_report.valid + corr_report.replaced + corr_report.invalid,
                      .valid_fraction = corr_report.valid_fraction(),
                      .seconds = result.seconds});
    return !stop_requested();
  };

  if (report.overlapped) {
    TwoStagePipeline<ReconstructedSet> stages(1);
    stages.run(produce, consume);
  } else {
    const std::function<bool()> never = [] { return false; };
    while (auto r = produce(never))
      if (!consume(*r)) break;
  }

  report.sets_in_file = results.set_count();
  report.mean_valid_fraction = report.sets_processed > 0 ? valid_sum / report.sets_processed : 0.0;
  report.stage_seconds += inputs.stage_seconds;  // the producer has finished
  const auto finish = [&] {
    report.seconds = seconds_between(started, Clock::now());
    const ProcessUsage usage = process_usage();
    report.cpu_user_seconds = usage.user - usage_at_start.user;
    report.cpu_system_seconds = usage.system - usage_at_start.system;
    report.minor_page_faults = usage.minor_faults - usage_at_start.minor_faults;
  };
  if (stop_requested()) {
    report.interrupted = true;  // the file is valid: every finished set is in it
    finish();
    return report;
  }
  finish_results(results, options, report);
  finish();
  return report;
}

}  // namespace tomorig::pipeline
