// tomorig bench recon: reconstruct a simulated case with several algorithms and particle
// densities, judge each result against the simulator's truth, and print JSON (issue 4).
//
// Cases whose dense truth volume would be too large to build (size-thesis-spray: 1080 x 1020 x
// 540 voxels, 2.4 GB as floats) are benchmarked for speed and memory only: no Q. Each
// algorithm's peak RSS is its own: the kernel's high-water mark is reset before it runs.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/cli_vocabulary.h"
#include "bench_common.h"
#include "bench_recon_tuning.h"
#include "tomorig/pipeline/report_json.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/particles/extraction.h"
#include "tomorig/processing/quality/quality_report.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/processing/reconstruction/smoothing.h"
#include "tomorig/simulators/simulated_rig.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::bench {

using pipeline::SessionCameras;
using pipeline::grid_from_session;
using pipeline::parse_grid;
using pipeline::session_cameras;
using pipeline::to_json;

namespace {

struct BenchReconArgs {
  std::string case_name = "tpiv-thesis";
  std::vector<double> ppp;  // empty: the case's own density (default_ppp)
  std::vector<std::string> algorithms{"mlos", "fmart"};
  int iterations = 0;
  double relaxation = recon::ReconstructionOptions{}.relaxation;          // the library's default
  double mlos_threshold = recon::ReconstructionOptions{}.mlos_threshold;  // the library's default
  BenchReconTuning tuning;        // --sigma-px, --prune
  int patch = 0;                  // patch edge p; 0: the library default (ceil(4 sigma), odd)
  int repeat = 1;                 // rounds per algorithm; rounds after the first are "warm"
  std::string initial = "mlos";  // SMART/FMART start: MLOS intensities or 1 ("uniform", as the thesis)
  std::string grid;
  std::uint64_t seed = 1;
  int threads = 0;
  std::string json_out;
  // Post-smoothing of FMART volumes before judging them, as the thesis did (Sect. 3.2.2);
  // "0" turns it off. Both the smoothed and the raw figures are reported.
  std::string fmart_smoothing = kJudgingSmoothingVoxel;
  std::string session;  // a recorded session instead of a simulated case (no truth)
  std::string calib;
  std::size_t set = 0;
  int exposures = 0;  // 1: A only, 2: A and B (a double exposure); 0: the case's default
  double max_truth_mb = 1024.0;
};

// The density ../shared/benchmarks/README.md defines each case at: the spray scale case at
// 0.03 ppp (at 0.05 its support is 3.3 x larger), tpiv-thesis's headline figures at 0.05.
double default_ppp(const std::string& case_name) { return case_name == "size-thesis-spray" ? 0.03 : 0.05; }

// A double exposure for the speed-and-memory case (the thesis timed two volumes), one exposure
// otherwise.
int default_exposures(const std::string& case_name) { return case_name == "size-thesis-spray" ? 2 : 1; }

// Resets the process's peak resident set (VmHWM) to the current RSS, so that the next reading
// is the peak of what runs in between (Linux >= 4.0: "5" > /proc/self/clear_refs). False if the
// kernel does not allow it; then peaks are cumulative.
bool reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  if (!f) return false;
  f << "5";
  return static_cast<bool>(f.flush());
}

double read_peak_rss_mb() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  return 0.0;
}

double available_mb() {
  std::ifstream f("/proc/meminfo");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("MemAvailable:", 0) == 0) return std::stod(line.substr(13)) / 1024.0;  // kB
  return 0.0;
}

Vec3d parse_sigma(const std::string& text) {
  if (text == "0") return {};
  double v[3];
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf", &v[0], &v[1], &v[2]) != 3 || !(v[0] >= 0 && v[1] >= 0 && v[2] >= 0))
    throw bad_input(fmt::format("--smooth '{}' is not valid: give sx,sy,sz in voxels (>= 0), or 0 for none", text));
  return {v[0], v[1], v[2]};
}

nlohmann::json quality_json(const quality::QualityReport& q) {
  return {{"q_global", q.q_global},
          {"q_windowed", q.q_windowed},
          {"ghost_true_count_ratio", json_number(q.ghost_true_count_ratio)},
          {"true_ghost_intensity_ratio", json_number(q.true_ghost_intensity_ratio)},
          {"position_rms_voxel", {q.position_rms_voxel[0], q.position_rms_voxel[1], q.position_rms_voxel[2]}},
          {"detected_fraction", q.detected_fraction},
          {"reconstruction_snr", json_number(q.snr.ratio)},
          {"true_blobs", q.true_blobs},
          {"ghost_blobs", q.ghost_blobs}};
}

// Recorded data (no truth): per algorithm, the time, the support, the blob count (local maxima
// above 1 % of the brightest voxel, particles/extraction.h) and the intensity-versus-depth
// profile: the sum of each z-slice, normalised by the largest (thesis Fig. 5.9).
void run_session(const BenchReconArgs& args, const recon::ReconstructionOptions& base) {
  const storage::SessionReader session(args.session);
  if (args.set >= session.set_count())
    throw bad_input(fmt::format("--set {} is out of range: session '{}' has {} sets", args.set, args.session,
                                session.set_count()));
  const pipeline::SessionDescription description = pipeline::describe_session(session);
  const SessionCameras cameras = session_cameras(description, args.calib);
  recon::ReconstructionInput input;
  input.cameras = cameras.pointers();
  input.grid = args.grid.empty() ? grid_from_session(description) : parse_grid(args.grid);
  for (const storage::SessionCamera& c : session.info().cameras) input.sensor_sizes.push_back({c.width, c.height});
  const FrameSet set = session.read_set(args.set);
  for (const auto& c : set.cameras) input.images.push_back(c.a.image);
  const VoxelGrid& g = input.grid;
  nlohmann::json results = nlohmann::json::array();
  for (const std::string& algorithm : args.algorithms) {
    recon::ReconstructionOptions options = base;
    options.algorithm = algorithm;
    reset_peak_rss();
    recon::ReconstructionReport report;
    const SparseVolume volume = recon::make_reconstructor(options)->reconstruct(input, report);
    std::vector<double> slice(static_cast<std::size_t>(g.nz), 0.0);
    const std::size_t per_slice = static_cast<std::size_t>(g.nx) * g.ny;
    for (std::size_t n = 0; n < volume.size(); ++n) slice[volume.index[n] / per_slice] += volume.intensity[n];
    const double top = *std::max_element(slice.begin(), slice.end());
    nlohmann::json profile = nlohmann::json::array();
    for (std::size_t k = 0; k < slice.size(); ++k)
      profile.push_back({{"k", k}, {"z_mm", g.centre_of(0, 0, static_cast<double>(k)).z},
                         {"intensity", top > 0 ? slice[k] / top : 0.0}});
    particles::ExtractionOptions extraction;
    extraction.threads = args.threads;
    const particles::ExtractionReport blobs = particles::extract_particles(volume, extraction);
    fmt::print(stderr, "  {:6} {:.2f} s, {} blobs  {}\n", algorithm, report.seconds, blobs.particles.size(),
               report.brief());
    results.push_back({{"algorithm", algorithm},
                       {"iterations", report.iterations},
                       {"seconds", report.seconds},
                       {"peak_rss_mb", read_peak_rss_mb()},
                       {"active_voxels", report.active_voxels},
                       {"nonzero_voxels", report.nonzero_voxels},
                       {"blobs", blobs.particles.size()},
                       {"blob_peak_cutoff", blobs.peak_cutoff},
                       {"intensity_vs_depth", profile},
                       {"report", to_json(report)}});
  }
  write_json({{"session", args.session},
              {"calibration", cameras.source},
              {"set", args.set},
              {"exposure", "A"},
              {"grid", {{"n", {g.nx, g.ny, g.nz}}, {"voxel_mm", g.voxel_size}, {"origin_mm", {g.origin.x, g.origin.y, g.origin.z}}}},
              {"mlos_threshold", args.mlos_threshold},
              {"machine", machine_json()},
              {"results", results}},
             args.json_out);
}

void run(const BenchReconArgs& args) {
  recon::ReconstructionOptions base;
  base.relaxation = args.relaxation;
  base.mlos_threshold = args.mlos_threshold;
  args.tuning.apply(base);
  base.mlos_initial_intensity = args.initial == "mlos";
  base.patch_size = args.patch;
  base.threads = args.threads;
  if (args.iterations > 0) base.max_iterations = args.iterations;
  for (const std::string& a : args.algorithms) {  // refuse a typo before minutes of work
    recon::ReconstructionOptions o = base;
    o.algorithm = a;
    o.validate();
    recon::make_reconstructor(o);
  }
  if (!args.session.empty()) return run_session(args, base);

  const Vec3d smoothing = parse_sigma(args.fmart_smoothing);
  const int exposures = args.exposures > 0 ? args.exposures : default_exposures(args.case_name);
  if (exposures > 2) throw bad_input(fmt::format("--exposures {} is not valid: give --exposure a (A) or both (A and B)", exposures));
  const bool peaks_reset = reset_peak_rss();
  nlohmann::json results = nlohmann::json::array();
  VoxelGrid case_grid;
  nlohmann::json quality_note;
  const std::vector<double> densities = args.ppp.empty() ? std::vector<double>{default_ppp(args.case_name)} : args.ppp;
  for (const double ppp : densities) {
    sim::SimulationOptions sim_options;
    sim_options.case_name = args.case_name;
    sim_options.ppp = ppp;
    sim_options.seed = args.seed;
    const sim::SimulatedRig rig(sim_options);
    const VoxelGrid grid = args.grid.empty() ? rig.case_definition().grid : parse_grid(args.grid);
    case_grid = grid;
    fmt::print(stderr, "{} at {} ppp: rendering {} particles...\n", args.case_name, ppp, rig.particles_per_set());
    const sim::SimulatedSet set = rig.render_set(0);

    auto input_of = [&](int exposure) {
      recon::ReconstructionInput input;
      for (std::size_t c = 0; c < rig.cameras().size(); ++c) {
        input.cameras.push_back(&rig.cameras()[c].model);
        const auto& frames = set.frames.cameras[c];
        input.images.push_back(exposure == 0 ? frames.a.image : frames.b.image);
        input.sensor_sizes.push_back({rig.cameras()[c].spec.width, rig.cameras()[c].spec.height});
      }
      input.grid = grid;
      args.tuning.apply(input);
      return input;
    };
    // Q needs the dense truth volume (and the quality code's own dense copies): judge only
    // grids whose truth fits --max-truth-mb.
    const double truth_mb = 4.0 * static_cast<double>(grid.voxel_count()) / (1024.0 * 1024.0);
    std::unique_ptr<quality::QualityEvaluator> judge;
    if (truth_mb <= args.max_truth_mb)
      judge = std::make_unique<quality::QualityEvaluator>(grid, set.particles_a);
    else
      quality_note = fmt::format("not judged: the dense truth volume would take {:.0f} MB (> --max-truth-mb {:.0f})",
                                 truth_mb, args.max_truth_mb);

    for (const std::string& algorithm : args.algorithms) {
      recon::ReconstructionOptions options = base;
      options.algorithm = algorithm;
      reset_peak_rss();
      double seconds = 0.0, peak = 0.0;
      // CPU seconds of the whole process over the reconstructions: on a shared machine, where wall
      // time depends on the other load, CPU / threads is the wall time the work would take alone.
      const double cpu_start = process_cpu_seconds();
      recon::ReconstructionReport report, first_report;
      SparseVolume volume;
      double cpu_seconds = 0.0;
      // Round 0 is the cold run: every buffer is fresh memory, which this VM makes expensive
      // (docs/performance.md, "Page faults"). Later rounds reuse memory just freed, as every
      // set after the first does in `tomorig process`: the steady state of a processing run.
      std::vector<double> warm_seconds;
      for (int round = 0; round < args.repeat; ++round) {
        double round_seconds = 0.0;
        for (int e = exposures - 1; e >= 0; --e) {  // B first, so that A's volume is the one kept
          volume = {};  // the previous exposure's volume would only inflate the peak
          volume = recon::make_reconstructor(options)->reconstruct(input_of(e), report);
          round_seconds += report.seconds;
          peak = std::max(peak, read_peak_rss_mb());
          if (e == 0 && round == 0) first_report = report;
          fmt::print(stderr, "  {:6} exposure {}{}: {:.2f} s  {}\n", algorithm, e == 0 ? "A" : "B",
                     round == 0 ? "" : fmt::format(" (round {})", round + 1), report.seconds, report.brief());
        }
        if (round == 0) {
          seconds = round_seconds;
          cpu_seconds = process_cpu_seconds() - cpu_start;
        } else {
          warm_seconds.push_back(round_seconds);
        }
      }
      nlohmann::json r;
      if (judge) {
        // Judged on exposure A (the truth is particles_a), which ran last.
        const bool smooth = algorithm == "fmart" && (smoothing.x > 0 || smoothing.y > 0 || smoothing.z > 0);
        const quality::QualityReport raw = judge->evaluate(volume);
        const quality::QualityReport q = smooth ? judge->evaluate(recon::gaussian_smooth(volume, smoothing)) : raw;
        fmt::print(stderr, "  {:6} Q {:.3f} (windowed {:.3f})\n", algorithm, q.q_global, q.q_windowed);
        r = quality_json(q);
        r["smoothing_sigma_voxel"] = smooth ? nlohmann::json{smoothing.x, smoothing.y, smoothing.z} : nlohmann::json();
        r["unsmoothed"] = quality_json(raw);
      } else {
        r["q_global"] = nullptr;
        r["q_windowed"] = nullptr;
        r["quality"] = quality_note;
      }
      r["algorithm"] = algorithm;
      r["ppp"] = ppp;
      r["exposures"] = exposures;
      r["iterations"] = first_report.iterations;
      r["seconds"] = seconds;  // all exposures
      r["seconds_per_exposure"] = seconds / exposures;
      if (!warm_seconds.empty()) {
        std::sort(warm_seconds.begin(), warm_seconds.end());
        r["seconds_warm_median"] = warm_seconds[warm_seconds.size() / 2];
        r["seconds_warm_min"] = warm_seconds.front();
        r["warm_rounds"] = warm_seconds.size();
      }
      r["cpu_seconds"] = cpu_seconds;
      r["peak_rss_mb"] = peaks_reset ? peak : first_report.peak_rss_mb;
      r["peak_rss_is_per_algorithm"] = peaks_reset;
      r["active_voxels"] = first_report.active_voxels;
      r["report"] = to_json(first_report);
      results.push_back(std::move(r));
    }
  }
  // The memory floor, measured last so that its buffer does not count in any algorithm's peak;
  // skipped (null) if the buffer would not fit in memory.
  const std::size_t floats = case_grid.voxel_count();
  const double buffer_mb = 4.0 * static_cast<double>(floats) / (1024.0 * 1024.0);
  nlohmann::json memory_pass = nullptr;
  if (buffer_mb < 0.8 * available_mb()) {
    double best = memory_pass_seconds(floats);  // the best of 2: the machine is shared
    best = std::min(best, memory_pass_seconds(floats));
    memory_pass = best;
    for (auto& r : results) {
      r["memory_pass_multiple"] = r["seconds_per_exposure"].get<double>() / best;
    }
  }
  const nlohmann::json out = {{"case", args.case_name},
                              {"grid", {case_grid.nx, case_grid.ny, case_grid.nz}},
                              {"exposure", exposures == 1 ? "A" : "A+B"},
                              {"mlos_threshold", args.mlos_threshold},
                              {"prune_fraction", args.tuning.prune_in_effect()},
                              {"initial_intensity", args.initial},
                              {"sigma_px", args.tuning.sigma_json()},
                              {"patch", args.patch},
                              {"seed", args.seed},
                              {"machine", machine_json()},
                              {"results", results},
                              {"memory_pass_seconds", memory_pass},
                              {"memory_pass_buffer_mb", buffer_mb}};
  write_json(out, args.json_out);
}

}  // namespace

void add_bench_recon_command(CLI::App& bench) {
  auto args = std::make_shared<BenchReconArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "recon", "Reconstruct a simulated case with each algorithm and density; judge against the truth");
  cmd->add_option("--case", args->case_name, "Simulated case")->capture_default_str();
  cmd->add_option("--ppp", args->ppp, "Particle densities, e.g. --ppp 0.03,0.05,0.07 (default: the case's, 0.05 for tpiv-thesis, 0.03 "
                  "for size-thesis-spray)")
      ->delimiter(',');
  cmd->add_option("--algorithms", args->algorithms, "Algorithms: " + recon::algorithm_names())->delimiter(',');
  cmd->add_option("--iterations", args->iterations, "Iterations of the iterative algorithms (0: their default)");
  cmd->add_option("--relaxation", args->relaxation, "Relaxation mu in (0, 2]")->capture_default_str();
  cmd->add_option("--mlos-threshold", args->mlos_threshold, "MLOS empty-pixel fraction of the image maximum")
      ->capture_default_str();
  args->tuning.add_options(*cmd);
  cmd->add_option("--patch", args->patch, "Patch edge p of SMART/FMART/MART (0: ceil(4 sigma), odd, >= 3)")
      ->check(CLI::Range(0, 15))
      ->capture_default_str();
  cmd->add_option("--repeat", args->repeat,
                  "Reconstruct each case this many times: 'seconds' is the first (cold) round, "
                  "'seconds_warm_median'/'_min' the later ones, whose memory was just freed by the previous "
                  "round, as in the steady state of `tomorig process`")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--initial", args->initial,
                  "SMART/FMART starting intensities: mlos (the MLOS product) or uniform (1, as the thesis's FMART)")
      ->check(CLI::IsMember({"mlos", "uniform"}))
      ->capture_default_str();
  cmd->add_option("--grid", args->grid, "Override the case's grid: nx,ny,nz,voxel_mm[,cx,cy,cz]");
  cmd->add_option("--seed", args->seed, "Random seed of the particle field")->capture_default_str();
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: all cores)")->capture_default_str();
  cmd->add_option("--smooth", args->fmart_smoothing,
                  "Gaussian sigma x,y,z (voxel) applied to FMART volumes before judging them, as the thesis "
                  "did; 0: none")
      ->capture_default_str();
  cli::add_deprecated_option(*cmd, "--fmart-smoothing", args->fmart_smoothing, "--smooth");
  cli::add_session_argument(*cmd, args->session,
                            "Reconstruct exposure A of a recorded session instead (no truth): reports time, blob count "
                            "and the intensity-versus-depth profile");
  cmd->add_option("--calib", args->calib, "With --session: calibration file (TOML), or 'truth'");
  cmd->add_option("--set", args->set, "With --session: set index, 0-based")->capture_default_str();
  cmd->add_option_function<std::string>(
         "--exposure",
         [args](const std::string& e) {
           if (e == "a" || e == "A") args->exposures = 1;
           else if (e == "both") args->exposures = 2;
           else
             throw bad_input(fmt::format("--exposure '{}' is not valid here: bench recon reconstructs a (exposure A) "
                                         "or both (A and B, times summed: a double exposure)", e));
         },
         "a: reconstruct exposure A; both: A and B, times summed (a double exposure); default: both for "
         "size-thesis-spray, else a");
  cmd->add_option_function<int>(
         "--exposures",
         [args](int n) {
           cli::warn_deprecated("--exposures 1|2", "--exposure a|both");
           args->exposures = n;
         },
         "deprecated: use --exposure a|both")
      ->group("");
  cmd->add_option("--max-truth-mb", args->max_truth_mb,
                  "Judge Q only if the dense truth volume fits this many MB (else speed and memory only)")
      ->capture_default_str();
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json); --json alone, '-' or none: stdout")
      ->expected(0, 1);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
