// tomorig bench piv3d: the accuracy of the 3-D correlation on a simulated case (issue 5,
// thesis Sect. 3.2 / 5.4.3): one set rendered per density, its two exposures taken from the
// truth (Gaussian blobs at the true particles) or reconstructed, correlated with the
// multigrid + deformation scheme, and judged against the case's analytic flow (Eq. 3.13) at the
// interior nodes.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/cli_vocabulary.h"
#include "bench_common.h"
#include "bench_recon_tuning.h"
#include "tomorig/pipeline/correlation_args.h"
#include "tomorig/pipeline/report_json.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/correlation/correlate.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/processing/reconstruction/smoothing.h"
#include "tomorig/simulators/simulated_rig.h"
#include "tomorig/simulators/truth_volume.h"

namespace tomorig::bench {

using pipeline::CorrelationArgs;
using pipeline::add_correlation_flags;
using pipeline::correlation_options;
using pipeline::parse_grid;
using pipeline::to_json;

namespace {
using Clock = std::chrono::steady_clock;

struct BenchPiv3dArgs {
  std::string case_name = "tpiv-thesis";
  std::vector<double> ppp{0.05};
  std::vector<std::string> sources{"truth", "fmart"};
  std::string grid;
  bool reduced = false;
  double particles_per_window = 10.0;
  CorrelationArgs correlation;
  int iterations = 0;
  double relaxation = 0.0;  // 0: the library default
  BenchReconTuning tuning;  // --sigma-px, --prune
  double mlos_threshold = -1.0;  // < 0: the library default
  std::string fmart_smoothing = kJudgingSmoothingVoxel;
  std::uint64_t seed = 1;
  int threads = 0;
  std::string json_out;
  std::string errors_csv;
};

// The grid of --reduced: 128 x 128 voxels at the centre of the case grid, its full depth and
// resolution (a sixteenth of the volume). Full depth, because particles in front of or behind a
// thinner grid would still be imaged and reconstructed as ghosts inside it.
VoxelGrid reduced_grid(const VoxelGrid& full) {
  return VoxelGrid::centred(std::min(full.nx, 128), std::min(full.ny, 128), full.nz, full.voxel_size);
}

// The smallest window (multiple of 8 per axis, z possibly half of x and y) holding about
// `particles` particles at `density` particles per voxel.
piv::WindowSize auto_window(double density, double particles, const VoxelGrid& grid) {
  const double voxels = particles / std::max(density, 1e-12);
  piv::WindowSize best{64, 64, 64};
  double best_error = 1e300;
  for (int w = 8; w <= 64; w += 8)
    for (const int wz : {w, w / 2}) {
      if (wz < 8 || wz > grid.nz / 2 || w > grid.nx / 2 || w > grid.ny / 2) continue;
      // Cubes preferred: a flat window only where it fits the particle count clearly better.
      const double error = std::abs(std::log(static_cast<double>(w) * w * wz / voxels)) + (wz == w ? 0.0 : 0.1);
      if (error < best_error) {
        best_error = error;
        best = {w, w, wz};
      }
    }
  return best;
}

Vec3d parse_sigma(const std::string& text) {
  if (text == "0") return {};
  double v[3];
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf", &v[0], &v[1], &v[2]) != 3 || !(v[0] >= 0 && v[1] >= 0 && v[2] >= 0))
    throw bad_input(fmt::format("--smooth '{}' is not valid: give sx,sy,sz in voxels (>= 0), or 0", text));
  return {v[0], v[1], v[2]};
}

struct FieldError {
  Vec3d rms;                   // voxel, per component
  // The thesis's "error of the displacement magnitude" (Fig. 3.15): RMS of |d| - |d_true|. It is
  // not the length of the error vector: its FMART figure at 0.10 ppp (0.13) is below its
  // z-component alone (0.17), as are all its magnitude figures.
  double rms_magnitude = 0;
  double rms_error_vector = 0;  // RMS of |d - d_true|: the stricter figure, for comparison
  double valid_fraction = 0;
  std::size_t nodes = 0;   // interior nodes judged
};

// Interior nodes (the outermost layer excluded: their windows reach the volume's faces), vectors
// that are not invalid, against the flow at the node.
FieldError judge(const VectorField& f, const sim::Flow& flow, double voxel_size) {
  FieldError e;
  Vec3d sum2;
  double magnitude2 = 0;
  std::size_t measured = 0, valid = 0, interior = 0;
  for (int k = 1; k + 1 < f.nz; ++k)
    for (int j = 1; j + 1 < f.ny; ++j)
      for (int i = 1; i + 1 < f.nx; ++i) {
        ++interior;
        const std::size_t n = f.linear(i, j, k);
        if (f.status[n] == VectorStatus::valid) ++valid;
        if (f.status[n] == VectorStatus::invalid) continue;
        const Vec3d x{f.origin.x + i * f.spacing.x, f.origin.y + j * f.spacing.y, f.origin.z + k * f.spacing.z};
        const Vec3d truth = flow.displacement(x) * (1.0 / voxel_size);
        const Vec3f& d = f.displacement[n];
        const Vec3d r{d.x - truth.x, d.y - truth.y, d.z - truth.z};
        sum2 = sum2 + Vec3d{r.x * r.x, r.y * r.y, r.z * r.z};
        const double length = std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.y) * d.y +
                                        static_cast<double>(d.z) * d.z);
        const double m = length - std::sqrt(truth.x * truth.x + truth.y * truth.y + truth.z * truth.z);
        magnitude2 += m * m;
        ++measured;
      }
  if (measured > 0) {
    e.rms = {std::sqrt(sum2.x / measured), std::sqrt(sum2.y / measured), std::sqrt(sum2.z / measured)};
    e.rms_magnitude = std::sqrt(magnitude2 / measured);
    e.rms_error_vector = std::sqrt((sum2.x + sum2.y + sum2.z) / measured);
  }
  e.valid_fraction = interior > 0 ? static_cast<double>(valid) / interior : 0.0;
  e.nodes = interior;
  return e;
}

// One line per node (all layers): index, position (voxel), measured and true displacement,
// status, peak; for looking at where the error sits.
void write_errors_csv(const std::string& path, const std::string& source, double ppp, const VectorField& f,
                      const sim::Flow& flow, const VoxelGrid& grid) {
  std::FILE* out = std::fopen(path.c_str(), "a");
  if (!out) throw runtime_error(fmt::format("cannot open --errors-csv '{}' for appending", path));
  for (int k = 0; k < f.nz; ++k)
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i) {
        const std::size_t n = f.linear(i, j, k);
        const Vec3d x{f.origin.x + i * f.spacing.x, f.origin.y + j * f.spacing.y, f.origin.z + k * f.spacing.z};
        const Vec3d v = grid.voxel_of(x);
        const Vec3d t = flow.displacement(x) * (1.0 / grid.voxel_size);
        const Vec3f& d = f.displacement[n];
        fmt::print(out, "{},{},{},{},{},{},{:.3f},{:.3f},{:.3f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{},{:.4f}\n", source,
                   ppp, i, j, k, f.nx, v.x, v.y, v.z, d.x, d.y, d.z, t.x, t.y, t.z, static_cast<int>(f.status[n]), f.peak[n]);
      }
  std::fclose(out);
}

// Per pass: where the correlation's time went, beside the pass's FFT floor.
void print_breakdown(const piv::CorrelationReport& report, const piv::FftFloor& floor) {
  for (std::size_t p = 0; p < report.passes.size(); ++p) {
    const piv::PassReport& r = report.passes[p];
    fmt::print(stderr,
               "    pass {} ({}, {} x {} x {} nodes, {} empty, {:.1f} % occupied, {} by FFT): {:.2f} s = deformation {:.2f} + "
               "windows {:.2f} + validation {:.2f}; window thread-s: load {:.2f}, {} {:.2f}, peak {:.2f}; FFT floor {:.2f} s\n",
               p, r.method, r.nodes_x, r.nodes_y, r.nodes_z, r.empty_windows, 100.0 * r.occupied_fraction, r.fft_fallbacks,
               r.seconds, r.seconds_deformation,
               r.seconds_windows, r.seconds_validation, r.thread_seconds_load, r.method, r.thread_seconds_correlation,
               r.thread_seconds_peak, p < floor.pass_seconds.size() ? floor.pass_seconds[p] : 0.0);
  }
}

// The options of a reconstructed source, validated (tomorig::Error naming a bad field).
recon::ReconstructionOptions reconstruction_options(const BenchPiv3dArgs& args, const std::string& source) {
  recon::ReconstructionOptions o;
  o.algorithm = source;
  o.threads = args.threads;
  if (args.iterations > 0) o.max_iterations = args.iterations;
  if (args.relaxation > 0) o.relaxation = args.relaxation;
  args.tuning.apply(o);
  if (args.mlos_threshold >= 0) o.mlos_threshold = args.mlos_threshold;
  o.validate();
  return o;
}

void run(const BenchPiv3dArgs& args) {
  // Refuse a typo or a bad setting before minutes of rendering.
  for (const std::string& s : args.sources)
    if (s != "truth") recon::make_reconstructor(reconstruction_options(args, s));
  const Vec3d smoothing = parse_sigma(args.fmart_smoothing);
  nlohmann::json results = nlohmann::json::array();
  VoxelGrid grid;
  for (const double ppp : args.ppp) {
    sim::SimulationOptions sim_options;
    sim_options.case_name = args.case_name;
    sim_options.ppp = ppp;
    sim_options.seed = args.seed;
    sim_options.threads = args.threads;
    const sim::SimulatedRig rig(sim_options);
    grid = !args.grid.empty() ? parse_grid(args.grid)
           : args.reduced     ? reduced_grid(rig.case_definition().grid)
                              : rig.case_definition().grid;
    fmt::print(stderr, "{} at {} ppp: rendering {} particles...\n", args.case_name, ppp, rig.particles_per_set());
    const sim::SimulatedSet set = rig.render_set(0);

    // Density inside the grid from the true particles, for the window size.
    std::size_t inside = 0;
    for (const Vec3d& p : set.particles_a) {
      const Vec3d v = grid.voxel_of(p);
      inside += v.x >= -0.5 && v.y >= -0.5 && v.z >= -0.5 && v.x < grid.nx - 0.5 && v.y < grid.ny - 0.5 &&
                v.z < grid.nz - 0.5;
    }
    const double density = static_cast<double>(inside) / static_cast<double>(grid.voxel_count());
    CorrelationArgs corr_args = args.correlation;
    corr_args.threads = args.threads;
    if (args.correlation.window == "auto") {
      const piv::WindowSize w = auto_window(density, args.particles_per_window, grid);
      corr_args.window = fmt::format("{},{},{}", w.x, w.y, w.z);
    }
    const piv::CorrelationOptions options = correlation_options(corr_args);
    options.validate(grid);
    const piv::WindowSize w = options.passes.back().window;
    const double particles_per_window = density * w.x * w.y * w.z;
    fmt::print(stderr, "  grid {} x {} x {}, window {} x {} x {} (~{:.1f} particles), overlap {}\n", grid.nx, grid.ny,
               grid.nz, w.x, w.y, w.z, particles_per_window, corr_args.overlap);

    for (const std::string& source : args.sources) {
      const auto start = Clock::now();
      SparseVolume a, b;
      nlohmann::json recon_reports = nlohmann::json::object();
      if (source == "truth") {
        a = sim::truth_volume(grid, set.particles_a);
        b = sim::truth_volume(grid, set.particles_b);
      } else {
        const auto reconstructor = recon::make_reconstructor(reconstruction_options(args, source));
        recon::ReconstructionInput input;
        for (std::size_t c = 0; c < rig.cameras().size(); ++c) {
          input.cameras.push_back(&rig.cameras()[c].model);
          input.sensor_sizes.push_back({rig.cameras()[c].spec.width, rig.cameras()[c].spec.height});
        }
        input.grid = grid;
        args.tuning.apply(input);
        const bool smooth = source == "fmart" && (smoothing.x > 0 || smoothing.y > 0 || smoothing.z > 0);
        for (const Exposure e : {Exposure::A, Exposure::B}) {
          input.images.clear();
          for (const CameraFrames& c : set.frames.cameras) input.images.push_back(c[e].image);
          recon::ReconstructionReport report;
          SparseVolume v = reconstructor->reconstruct(input, report);
          if (smooth) v = recon::gaussian_smooth(v, smoothing, args.threads);
          recon_reports[e == Exposure::A ? "a" : "b"] = to_json(report);
          (e == Exposure::A ? a : b) = std::move(v);
        }
      }
      piv::CorrelationReport report;
      const VectorField field = piv::correlate(a, b, options, report);
      const double total = std::chrono::duration<double>(Clock::now() - start).count();
      // The floor in the same run, same threads and windows: the FFTs alone.
      const piv::FftFloor floor = piv::measure_fft_floor(grid, options);
      const double floor_ratio = floor.seconds_total > 0 ? report.seconds_total / floor.seconds_total : 0.0;
      const FieldError e = judge(field, rig.flow(), grid.voxel_size);
      if (!args.errors_csv.empty()) write_errors_csv(args.errors_csv, source, ppp, field, rig.flow(), grid);
      fmt::print(stderr, "  {:6} RMS magnitude {:.3f} voxel, error vector {:.3f} (x {:.3f}, y {:.3f}, z {:.3f}), {:.1f} % valid, "
                         "correlation {:.1f} s, total {:.1f} s\n",
                 source, e.rms_magnitude, e.rms_error_vector, e.rms.x, e.rms.y, e.rms.z, 100.0 * e.valid_fraction,
                 report.seconds_total, total);
      print_breakdown(report, floor);
      fmt::print(stderr, "  {:6} correlation {:.2f} s = {:.2f} x its FFT floor ({:.2f} s measured now)\n", source,
                 report.seconds_total, floor_ratio, floor.seconds_total);
      results.push_back({{"source", source},
                         {"ppp", ppp},
                         {"rms_voxel", {e.rms.x, e.rms.y, e.rms.z}},
                         {"rms_magnitude_voxel", e.rms_magnitude},
                         {"rms_error_vector_voxel", e.rms_error_vector},
                         {"valid_fraction", e.valid_fraction},
                         {"seconds_correlation", report.seconds_total},
                         {"seconds_final_pass", report.passes.empty() ? 0.0 : report.passes.back().seconds},
                         {"seconds_fft_floor", floor.seconds_total},
                         {"fft_floor_pass_seconds", floor.pass_seconds},
                         {"ratio_to_fft_floor", floor_ratio},
                         {"seconds_total", total},
                         {"interior_nodes", e.nodes},
                         {"window", {w.x, w.y, w.z}},
                         {"particles_per_window", particles_per_window},
                         {"correlation_report", to_json(report)},
                         {"reconstruction", recon_reports}});
    }
  }
  CorrelationArgs shown = args.correlation;
  const nlohmann::json out = {{"case", args.case_name},
                              {"grid", {grid.nx, grid.ny, grid.nz}},
                              {"voxel_mm", grid.voxel_size},
                              {"overlap", shown.overlap},
                              {"deformation_passes", shown.deformation_passes},
                              {"weighting", shown.weighting},
                              {"gaussian_sigma", shown.gaussian_sigma},
                              {"fmart_smoothing", args.fmart_smoothing},
                              {"sigma_px", args.tuning.sigma_json()},
                              {"relaxation", args.relaxation > 0 ? nlohmann::json(args.relaxation) : nlohmann::json("default")},
                              {"iterations", args.iterations > 0 ? nlohmann::json(args.iterations) : nlohmann::json("default")},
                              {"prune_fraction", args.tuning.prune_in_effect()},
                              {"mlos_threshold", args.mlos_threshold >= 0 ? nlohmann::json(args.mlos_threshold) : nlohmann::json("default")},
                              {"seed", args.seed},
                              {"boundary_nodes_excluded", 1},
                              {"machine", machine_json()},
                              {"results", results}};
  write_json(out, args.json_out);
}

}  // namespace

void add_bench_piv3d_command(CLI::App& bench) {
  auto args = std::make_shared<BenchPiv3dArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "piv3d", "Correlate a simulated case's volumes (truth or reconstructed) and judge them against the flow");
  cmd->add_option("--case", args->case_name, "Simulated case")->capture_default_str();
  cmd->add_option("--ppp", args->ppp, "Particle densities, e.g. --ppp 0.05,0.10")->delimiter(',');
  cmd->add_option("--source", args->sources, "Volume sources: truth and/or " + recon::algorithm_names())
      ->delimiter(',');
  cmd->add_option("--grid", args->grid, "Override the case's grid: nx,ny,nz,voxel_mm[,cx,cy,cz]");
  cmd->add_flag("--reduced", args->reduced, "A 128 x 128 voxel grid of full depth at the case's centre: a quick variant");
  args->correlation.window = "auto";  // --window auto: the window holding --particles-per-window particles
  add_correlation_flags(*cmd, args->correlation);
  cmd->add_option("--particles-per-window", args->particles_per_window, "Target of --window auto")
      ->capture_default_str();
  cmd->add_option("--iterations", args->iterations, "Reconstruction iterations (0: the algorithm's default)");
  cmd->add_option("--relaxation", args->relaxation, "Relaxation mu of MART/SMART/FMART, (0, 2] (0: the library default)")
      ->check(CLI::Range(0.0, 2.0))
      ->capture_default_str();
  args->tuning.add_options(*cmd);
  cmd->add_option("--mlos-threshold", args->mlos_threshold,
                  "MLOS empty-pixel fraction of the image maximum (negative: the library default)")
      ->capture_default_str();
  cmd->add_option("--smooth", args->fmart_smoothing,
                  "Gaussian sigma x,y,z (voxel) applied to FMART volumes before correlation, as the thesis did; 0: none")
      ->capture_default_str();
  cli::add_deprecated_option(*cmd, "--fmart-smoothing", args->fmart_smoothing, "--smooth");
  cmd->add_option("--seed", args->seed, "Random seed of the particle field")->capture_default_str();
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: all cores)")->capture_default_str();
  cmd->add_option("--errors-csv", args->errors_csv,
                  "Append one CSV line per node (source, ppp, i, j, k, nx, position, measured and true displacement "
                  "in voxel, status, peak) to this file");
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json); --json alone, '-' or none: stdout")
      ->expected(0, 1);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
