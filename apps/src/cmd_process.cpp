// tomorig process: the back-end. For each set of a session: preprocess the frames, reconstruct
// both exposures, correlate them; the vector fields and their ensemble statistics go into a
// results file (storage/results_file.h) that is complete after every set, so an interrupted run
// resumes where it stopped. Reconstruction of one set overlaps correlation of the previous one.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "tomorig/pipeline/correlation_args.h"
#include "tomorig/pipeline/two_stage_pipeline.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "process_progress.h"
#include "tomorig/pipeline/slice_png.h"
#include "tomorig/pipeline/report_json.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/processing/reconstruction/smoothing.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {

using pipeline::CorrelationArgs;
using pipeline::ReconstructionSetup;
using pipeline::SessionCameras;
using pipeline::SessionPreprocessor;
using pipeline::TwoStagePipeline;
using pipeline::add_correlation_flags;
using pipeline::correlation_options;
using pipeline::reconstruction_setup;
using pipeline::session_cameras;
using pipeline::to_json;
using pipeline::write_slice_png;
using rig::StopSignalGuard;

namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct ProcessArgs {
  std::string session;
  std::string calib;
  std::string config;
  std::string out;
  std::string algorithm;
  int iterations = 0;
  double relaxation = 1.0;
  std::string grid;
  double sigma_px = 0.5;  // as `tomorig reconstruct`
  std::vector<double> smooth;
  std::int64_t dt_ns = 0;
  std::uint64_t max_sets = 0;
  int threads = 0;
  bool overwrite = false;
  bool sequential = false;
  bool json = false;
  std::string png;
  CorrelationArgs correlation;
};

// FNV-1a: stable across builds and machines, unlike std::hash.
std::uint64_t fnv1a(const unsigned char* data, std::size_t size, std::uint64_t hash = 1469598103934665603ull) {
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 1099511628211ull;
  return hash;
}

// What identifies a recording whatever its path: when it was made, its cameras, its rig config
// and the pixels of its first frame (two simulations of one rig differ only there).
std::string session_identity(const storage::SessionReader& session) {
  const std::string& toml = session.info().rig_config_toml;
  const std::uint64_t config_hash = fnv1a(reinterpret_cast<const unsigned char*>(toml.data()), toml.size());
  std::uint64_t pixel_hash = 0;
  const FrameSet first = session.read_set(0);
  for (const CameraFrames& c : first.cameras)
    if (c.a.present()) {
      const Image& image = c.a.image;
      for (int y = 0; y < image.height(); ++y)
        pixel_hash = fnv1a(reinterpret_cast<const unsigned char*>(image.data()) + y * image.stride_bytes(),
                           image.row_bytes(), pixel_hash == 0 ? 1469598103934665603ull : pixel_hash);
      break;
    }
  std::string cameras;
  for (const storage::SessionCamera& c : session.info().cameras)
    cameras += fmt::format("{}{}:{}x{}", cameras.empty() ? "" : ",", c.id, c.width, c.height);
  return fmt::format("{};{};config {:016x};pixels {:016x}", session.info().created_utc, cameras, config_hash,
                     pixel_hash);
}

nlohmann::json grid_json(const VoxelGrid& g) {
  return {{"nx", g.nx}, {"ny", g.ny}, {"nz", g.nz}, {"voxel_mm", g.voxel_size}, {"origin_mm", {g.origin.x, g.origin.y, g.origin.z}}};
}

std::string file_text(const std::string& path) {
  if (path.empty()) return "";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw bad_input(fmt::format("--config '{}' cannot be read; give the preprocessing chain TOML", path));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The reconstructed pair of one set, passed from the reconstruction stage to correlation.
struct ReconstructedSet {
  std::uint64_t index = 0;
  std::int64_t dt_ns = 0;
  SparseVolume a, b;
  nlohmann::json reports;
  Clock::time_point started;
};

// Available memory from /proc/meminfo (0 if unknown).
double available_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024.0;
  return 0.0;
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

void run(const ProcessArgs& args) {
  const auto started = Clock::now();
  const storage::SessionReader session(args.session);
  if (session.set_count() == 0) throw bad_input(fmt::format("session '{}' holds no set to process", args.session));
  const SessionCameras cameras = session_cameras(session, args.calib);

  // The rig config's processing.algorithm is deliberately not used: `process` reconstructs with
  // FMART unless --algorithm says otherwise (issue 5).
  ReconstructionSetup setup = reconstruction_setup(session, args.session, cameras,
                                                   {.algorithm = args.algorithm,
                                                    .algorithm_from_rig = false,
                                                    .iterations = args.iterations,
                                                    .relaxation = args.relaxation,
                                                    .threads = args.threads,
                                                    .grid = args.grid,
                                                    .sigma_px = args.sigma_px});
  const recon::ReconstructionOptions& recon_options = setup.options;
  const auto reconstructor = recon::make_reconstructor(recon_options);
  const recon::ReconstructionInput& input = setup.input;

  CorrelationArgs corr_args = args.correlation;
  corr_args.threads = args.threads;
  const piv::CorrelationOptions corr = correlation_options(corr_args);
  corr.validate(input.grid);  // an interrogation volume larger than the grid fails here, before any work

  // Every set needs a pulse separation for its velocities; find a missing one before hours of work.
  if (args.dt_ns < 0) throw bad_input(fmt::format("--dt-ns {} must be > 0", args.dt_ns));
  const std::uint64_t set_total =
      args.max_sets > 0 ? std::min<std::uint64_t>(args.max_sets, session.set_count()) : session.set_count();
  std::vector<std::int64_t> dt(set_total);
  for (std::uint64_t s = 0; s < set_total; ++s) {
    dt[s] = args.dt_ns > 0 ? args.dt_ns : session.set_record(s).dt_ns;
    if (dt[s] <= 0)
      throw bad_input(fmt::format("set {} of session '{}' has pulse separation dt = {} ns (missing), so its velocity "
                                  "cannot be computed; give the laser pulse separation with --dt-ns",
                                  s, args.session, dt[s]));
  }

  const std::string identity = session_identity(session);
  const nlohmann::json parameters = {
      {"grid", grid_json(input.grid)},
      {"reconstruction", {{"algorithm", recon_options.algorithm}, {"max_iterations", recon_options.max_iterations},
                          {"relaxation", recon_options.relaxation}, {"sigma_px", args.sigma_px},
                          {"smoothing_sigma_voxel", args.smooth}, {"cameras", cameras.source}}},
      {"preprocess", {{"chain_file", args.config}, {"chain_toml", file_text(args.config)}}},
      {"correlation", to_json(corr)},
      {"dt_override_ns", args.dt_ns}};
  std::error_code ec;
  if (!args.overwrite && fs::exists(args.out, ec)) check_existing_results(args.out, identity, parameters["grid"]);
  storage::ResultsWriter writer(args.out,
                                {.session_path = args.session,
                                 .session_identity = identity,
                                 .parameters_json = parameters.dump(),
                                 .voxel_size_mm = input.grid.voxel_size},
                                {.overwrite = args.overwrite});
  if (writer.resumed_sets() == 0) writer.write();  // an empty, valid file from the start: the path works

  std::vector<std::uint64_t> todo;
  for (std::uint64_t s = 0; s < set_total; ++s)
    if (!writer.has_set(s)) todo.push_back(s);
  if (writer.resumed_sets() > 0)
    fmt::print(stderr, "resuming {}: {} sets already finished, {} to do\n", args.out, writer.resumed_sets(), todo.size());

  SessionPreprocessor preprocessor(session, args.config);
  const StopSignalGuard stop_signal;

  // Two sets in flight (one reconstructing, one correlating) need about twice the dense volumes
  // of one: the correlator's float copies, deformed volumes and spline coefficients of both
  // exposures (~8 dense volumes), plus the reconstruction's working volumes (~4).
  const double per_set = 12.0 * static_cast<double>(input.grid.voxel_count()) * sizeof(float);
  const double memory = available_bytes();
  const bool overlap = !args.sequential && memory > 2.0 * per_set;
  fmt::print(stderr, "processing {} sets of {} with {} on a {} x {} x {} grid ({}), {} cameras, {}\n", todo.size(),
             args.session, recon_options.algorithm, input.grid.nx, input.grid.ny, input.grid.nz, cameras.source,
             input.cameras.size(),
             overlap ? "reconstruction and correlation overlapped" : "one set at a time");

  std::size_t next = 0;
  const auto produce = [&](const std::function<bool()>& stop) -> std::optional<ReconstructedSet> {
    if (next >= todo.size() || stop() || stop_signal.stop_requested()) return std::nullopt;
    ReconstructedSet r;
    r.index = todo[next++];
    r.dt_ns = dt[r.index];
    r.started = Clock::now();
    FrameSet set = session.read_set(r.index);
    preprocessor.apply(set);
    recon::ReconstructionInput in = input;
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      in.images.clear();
      for (const CameraFrames& c : set.cameras) {
        const Frame& f = c[e];
        if (!f.present())
          throw bad_input(fmt::format("session '{}' set {}: frame {} of camera {} is missing; process the other sets "
                                      "with --sets or repair the recording",
                                      args.session, r.index, e == Exposure::A ? "A" : "B", c.camera_id));
        in.images.push_back(f.image);
      }
      recon::ReconstructionReport report;
      SparseVolume v = reconstructor->reconstruct(in, report);
      if (!args.smooth.empty()) v = recon::gaussian_smooth(v, {args.smooth[0], args.smooth[1], args.smooth[2]}, args.threads);
      r.reports[e == Exposure::A ? "a" : "b"] = to_json(report);
      (e == Exposure::A ? r.a : r.b) = std::move(v);
    }
    return r;
  };

  ProgressLine progress(todo.size());
  double valid_sum = 0.0;
  std::uint64_t processed = 0;
  const auto consume = [&](ReconstructedSet& r) -> bool {
    if (stop_signal.stop_requested()) return false;
    piv::CorrelationReport report;
    storage::SetResult result;
    result.field = piv::correlate(r.a, r.b, corr, report);
    result.set_index = r.index;
    result.dt_ns = r.dt_ns;
    result.report_json = nlohmann::json{{"reconstruction", r.reports}, {"correlation", to_json(report)}}.dump();
    result.seconds = std::chrono::duration<double>(Clock::now() - r.started).count();
    writer.add(result);
    valid_sum += report.valid_fraction();
    ++processed;
    fmt::print(stderr, "\rset {} done: {} vectors, {:.1f} % valid, {:.1f} s\n", r.index, report.valid + report.replaced + report.invalid,
               100.0 * report.valid_fraction(), result.seconds);
    progress.set_done();
    return !stop_signal.stop_requested();
  };

  if (overlap) {
    TwoStagePipeline<ReconstructedSet> pipeline(1);
    pipeline.run(produce, consume);
  } else {
    const std::function<bool()> never = [] { return false; };
    while (auto r = produce(never))
      if (!consume(*r)) break;
  }

  const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
  const std::uint64_t in_file = writer.set_count();
  if (stop_signal.stop_requested())
    throw runtime_error(fmt::format("interrupted by {}: '{}' is valid and holds {} of {} sets; run the same command "
                                    "again to resume",
                                    stop_signal.signal_name(), args.out, in_file, set_total));

  // Summary: the mean field over the file's sets.
  writer.close();  // errors surface here rather than in the destructor
  const storage::EnsembleStatistics stats = writer.statistics();
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
  const Vec3d spread{std::sqrt(std::max(0.0, sum2.x * inv - mean_d.x * mean_d.x)),
                     std::sqrt(std::max(0.0, sum2.y * inv - mean_d.y * mean_d.y)),
                     std::sqrt(std::max(0.0, sum2.z * inv - mean_d.z * mean_d.z))};
  if (!args.png.empty()) {
    std::vector<bool> counted(stats.valid_count.size());
    for (std::size_t i = 0; i < counted.size(); ++i) counted[i] = stats.valid_count[i] > 0;
    write_slice_png(args.png, stats.nx, stats.ny, stats.nz, stats.nz / 2, stats.mean_displacement_voxel, counted);
  }
  const nlohmann::json summary = {
      {"out", args.out},
      {"xdmf", storage::ResultsWriter::sidecar_path(args.out).string()},
      {"session", args.session},
      {"sets_in_file", in_file},
      {"sets_processed", processed},
      {"sets_resumed", writer.resumed_sets()},
      {"nodes", {stats.nx, stats.ny, stats.nz}},
      {"mean_valid_fraction", processed > 0 ? valid_sum / processed : 0.0},
      {"mean_speed_m_s", nodes > 0 ? speed / nodes : 0.0},
      {"mean_displacement_voxel", {mean_d.x, mean_d.y, mean_d.z}},
      {"spatial_std_displacement_voxel", {spread.x, spread.y, spread.z}},
      {"seconds", seconds},
      {"sets_per_second", processed > 0 ? processed / seconds : 0.0}};
  if (args.json) {
    fmt::print("{}\n", summary.dump(2));
  } else {
    fmt::print("wrote {} and {}: {} sets ({} processed now, {} resumed), {} x {} x {} vectors, {:.1f} % valid, mean "
               "speed {:.4g} m/s, {:.1f} s ({:.3g} sets/s)\n",
               args.out, summary["xdmf"].get<std::string>(), in_file, processed, writer.resumed_sets(), stats.nx,
               stats.ny, stats.nz, 100.0 * summary["mean_valid_fraction"].get<double>(),
               summary["mean_speed_m_s"].get<double>(), seconds, summary["sets_per_second"].get<double>());
  }
}

}  // namespace

void add_process_command(CLI::App& root) {
  auto args = std::make_shared<ProcessArgs>();
  CLI::App* cmd = root.add_subcommand(
      "process", "Back-end: preprocess, reconstruct and correlate every set of a session into a results file");
  cmd->add_option("--session", args->session, "Session file (.h5)")->required();
  cmd->add_option("--calib", args->calib,
                  "Calibration file (TOML), or 'truth' for a simulated session's exact cameras (default: the truth "
                  "if present, else the rig config's calibration file)");
  cmd->add_option("--config", args->config,
                  "Preprocessing chain ([[preprocess.steps]] TOML, as for 'tomorig preprocess --chain'); default: none");
  cmd->add_option("-o,--out", args->out, "Results file (.h5); an existing one of the same session and parameters is "
                                         "resumed")
      ->required();
  cmd->add_option("--algorithm", args->algorithm, "Reconstruction algorithm: " + recon::algorithm_names() + " (default fmart)");
  cmd->add_option("--iterations", args->iterations, "Reconstruction iterations (default: the rig config's)");
  cmd->add_option("--relaxation", args->relaxation, "Relaxation mu in (0, 2]")->capture_default_str();
  cmd->add_option("--grid", args->grid, "Voxel grid nx,ny,nz,voxel_mm[,cx,cy,cz] (default: the rig config's [grid])");
  cmd->add_option("--sigma-px", args->sigma_px, "Gaussian sigma of the voxel-to-pixel weights, pixels")
      ->capture_default_str();
  cmd->add_option("--smooth", args->smooth, "Gaussian smoothing sigma x,y,z (voxel) of each reconstructed volume")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--dt-ns", args->dt_ns, "Pulse separation in ns, for sessions that did not record it");
  cmd->add_option("--max-sets", args->max_sets, "Process only the first N sets (0: all)");
  add_correlation_flags(*cmd, args->correlation);
  cmd->add_option("--threads", args->threads, "OpenMP threads per stage (0: all cores)")->capture_default_str();
  cmd->add_flag("--sequential", args->sequential, "Do not overlap reconstruction and correlation of different sets");
  cmd->add_flag("--overwrite", args->overwrite, "Start a new results file even if one exists");
  cmd->add_flag("--json", args->json, "Print the summary as JSON");
  cmd->add_option("--png", args->png,
                  "Also write a picture (PNG) of the mean field's middle z-slice: grey = in-plane magnitude, line = "
                  "direction, black = no valid vector");
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
