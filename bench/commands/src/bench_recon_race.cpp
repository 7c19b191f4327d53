// tomorig bench recon-race: FMART against SMART on the same sparse machinery (issue 4). For
// each density, both run from the same MLOS support with an iteration observer that judges the
// volume after every iteration against the simulator's truth (the judging time is excluded
// from the timings). Reported per algorithm and density: Q per iteration, seconds per
// iteration, the elapsed time at each iteration (set-up included), and the time each needs to
// reach a common target Q, with the ratio SMART / FMART.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/cli_vocabulary.h"
#include "bench_common.h"
#include "bench_recon_tuning.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/quality/quality_factor.h"
#include "tomorig/processing/quality/quality_report.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/processing/reconstruction/smoothing.h"
#include "tomorig/simulators/simulated_rig.h"

namespace tomorig::bench {

using pipeline::parse_grid;

namespace {

struct RaceArgs {
  std::string case_name = "tpiv-thesis";
  std::vector<double> ppp{0.03, 0.05, 0.10};
  int fmart_iterations = 12;
  int smart_iterations = 20;
  double fmart_relaxation = recon::ReconstructionOptions{}.relaxation;  // the library's default
  double smart_relaxation = 1.5;
  double mlos_threshold = recon::ReconstructionOptions{}.mlos_threshold;  // the library's default
  BenchReconTuning tuning;       // --sigma-px, --prune
  double q_target = 0.0;         // 0: the lower of the two algorithms' best Q, per density
  std::string smoothing = kJudgingSmoothingVoxel;
  std::string grid;
  std::uint64_t seed = 1;
  int threads = 0;
  std::string json_out;
};

Vec3d parse_smoothing(const std::string& text) {
  if (text == "0") return {};
  double v[3];
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf", &v[0], &v[1], &v[2]) != 3 || !(v[0] >= 0 && v[1] >= 0 && v[2] >= 0))
    throw bad_input(fmt::format("--smooth '{}' is not valid: give sx,sy,sz in voxels (>= 0), or 0 for none", text));
  return {v[0], v[1], v[2]};
}

struct Step {
  int iteration = 0;
  double q = 0.0;          // windowed Q after the smoothing (the figure the target refers to)
  double q_global = 0.0;   // global Q after the smoothing
  double q_raw = 0.0;      // windowed Q of the volume as reconstructed
  double seconds = 0.0;    // this iteration (0 for iteration 0, the MLOS start)
  double elapsed = 0.0;    // since the start of the call, set-up included
  std::size_t live_voxels = 0;
};

struct Run {
  std::string algorithm;
  double relaxation = 1.0;
  std::vector<Step> steps;  // iteration 0 (MLOS) first
  recon::ReconstructionReport report;

  double best_q() const {
    double best = 0;
    for (const Step& s : steps) best = std::max(best, s.q);
    return best;
  }
  // The first step reaching q, or null if none does.
  const Step* first_reaching(double q) const {
    for (const Step& s : steps)
      if (s.q >= q) return &s;
    return nullptr;
  }
  // Seconds of the iterations 1..last, without the set-up: on a loaded machine the set-up's
  // wall time varies more than the difference between the algorithms.
  double iteration_seconds_until(int last) const {
    double sum = 0;
    for (const Step& s : steps)
      if (s.iteration > 0 && s.iteration <= last) sum += s.seconds;
    return sum;
  }
  double mean_iteration_seconds() const {
    double sum = 0;
    int n = 0;
    for (const Step& s : steps)
      if (s.iteration > 0) {
        sum += s.seconds;
        ++n;
      }
    return n > 0 ? sum / n : 0.0;
  }
};

Run race_one(const std::string& algorithm, int iterations, double relaxation, const RaceArgs& args,
             const recon::ReconstructionInput& input, const quality::QualityEvaluator& judge, const Vec3d& smoothing) {
  recon::ReconstructionOptions o;
  o.algorithm = algorithm;
  o.max_iterations = iterations;
  o.relaxation = relaxation;
  o.mlos_threshold = args.mlos_threshold;
  o.threads = args.threads;
  args.tuning.apply(o);
  const bool smooth = smoothing.x > 0 || smoothing.y > 0 || smoothing.z > 0;

  Run run;
  run.algorithm = algorithm;
  run.relaxation = relaxation;
  auto reconstructor = recon::make_reconstructor(o);
  reconstructor->set_iteration_observer([&](const recon::IterationView& view) {
    // Only Q (Eq. 3.14, global and windowed, as bench recon reports it), not the blob
    // analysis: judging after every iteration must stay cheap.
    const SparseVolume volume = view.volume();
    const quality::WindowOptions windows;
    const quality::QualityFactor raw = quality::quality_factor(volume, judge.truth_volume(), windows, args.threads);
    const quality::QualityFactor q =
        smooth ? quality::quality_factor(recon::gaussian_smooth(volume, smoothing, args.threads), judge.truth_volume(),
                                         windows, args.threads)
               : raw;
    Step s;
    s.iteration = view.iteration;
    s.q = q.windowed;
    s.q_global = q.global;
    s.q_raw = raw.windowed;
    s.seconds = view.stats ? view.stats->seconds : 0.0;
    s.elapsed = view.elapsed_seconds;
    s.live_voxels = view.stats ? view.stats->live_voxels : volume.size();
    run.steps.push_back(s);
    fmt::print(stderr, "  {:5} it {:2}: Q {:.3f} (raw {:.3f})  {:.3f} s/it  {:.3f} s elapsed  {} voxels\n",
               algorithm, s.iteration, s.q, s.q_raw, s.seconds, s.elapsed, s.live_voxels);
  });
  reconstructor->reconstruct(input, run.report);
  return run;
}

nlohmann::json run_json(const Run& run, double target) {
  nlohmann::json steps = nlohmann::json::array();
  for (const Step& s : run.steps)
    steps.push_back({{"iteration", s.iteration},
                     {"q_windowed", s.q},
                     {"q_global", s.q_global},
                     {"q_windowed_unsmoothed", s.q_raw},
                     {"seconds", s.seconds},
                     {"elapsed_seconds", s.elapsed},
                     {"live_voxels", s.live_voxels}});
  const Step* hit = run.first_reaching(target);
  return {{"algorithm", run.algorithm},
          {"relaxation", run.relaxation},
          {"iterations", run.report.iterations},
          {"setup_seconds", run.report.setup_seconds},
          {"seconds", run.report.seconds},
          {"seconds_per_iteration", run.mean_iteration_seconds()},
          {"active_voxels", run.report.active_voxels},
          {"peak_rss_mb", run.report.peak_rss_mb},
          {"best_q_windowed", run.best_q()},
          {"iterations_to_target", hit ? nlohmann::json(hit->iteration) : nlohmann::json()},
          {"seconds_to_target", hit ? nlohmann::json(hit->elapsed) : nlohmann::json()},
          {"iteration_seconds_to_target", hit ? nlohmann::json(run.iteration_seconds_until(hit->iteration))
                                              : nlohmann::json()},
          {"per_iteration", steps}};
}

void run(const RaceArgs& args) {
  const Vec3d smoothing = parse_smoothing(args.smoothing);
  for (const auto& [name, it] : {std::pair{"--fmart-iterations", args.fmart_iterations},
                                 std::pair{"--smart-iterations", args.smart_iterations}})
    if (it < 1) throw bad_input(fmt::format("{} = {} must be >= 1", name, it));
  if (!(args.q_target >= 0 && args.q_target <= 1))
    throw bad_input(fmt::format("--q-target = {} must be in [0, 1] (0: the lower best Q of the two)", args.q_target));
  if (args.ppp.empty()) throw bad_input("--ppp: give at least one density, e.g. --ppp 0.03,0.05,0.10");
  for (const auto& [a, mu] : {std::pair{"fmart", args.fmart_relaxation}, std::pair{"smart", args.smart_relaxation}}) {
    recon::ReconstructionOptions o;  // refuse a bad option before minutes of rendering
    o.algorithm = a;
    o.relaxation = mu;
    o.mlos_threshold = args.mlos_threshold;
    args.tuning.apply(o);
    o.validate();
  }

  nlohmann::json results = nlohmann::json::array();
  VoxelGrid case_grid;
  for (const double ppp : args.ppp) {
    sim::SimulationOptions sim_options;
    sim_options.case_name = args.case_name;
    sim_options.ppp = ppp;
    sim_options.seed = args.seed;
    const sim::SimulatedRig rig(sim_options);
    const VoxelGrid grid = args.grid.empty() ? rig.case_definition().grid : parse_grid(args.grid);
    case_grid = grid;
    fmt::print(stderr, "{} at {} ppp: rendering {} particles...\n", args.case_name, ppp, rig.particles_per_set());
    const sim::SimulatedSet set = rig.render_set(0);
    recon::ReconstructionInput input;
    for (std::size_t c = 0; c < rig.cameras().size(); ++c) {
      input.cameras.push_back(&rig.cameras()[c].model);
      input.images.push_back(set.frames.cameras[c].a.image);
      input.sensor_sizes.push_back({rig.cameras()[c].spec.width, rig.cameras()[c].spec.height});
    }
    input.grid = grid;
    args.tuning.apply(input);
    const quality::QualityEvaluator judge(grid, set.particles_a);

    const Run fmart = race_one("fmart", args.fmart_iterations, args.fmart_relaxation, args, input, judge, smoothing);
    const Run smart = race_one("smart", args.smart_iterations, args.smart_relaxation, args, input, judge, smoothing);
    const double target = args.q_target > 0 ? args.q_target : std::min(fmart.best_q(), smart.best_q());
    const Step* f = fmart.first_reaching(target);
    const Step* s = smart.first_reaching(target);
    nlohmann::json r = {{"ppp", ppp},
                        {"target_q_windowed", target},
                        {"fmart", run_json(fmart, target)},
                        {"smart", run_json(smart, target)}};
    r["speedup_time_to_target"] =
        f && s && f->elapsed > 0 ? nlohmann::json(s->elapsed / f->elapsed) : nlohmann::json();
    r["speedup_iteration_time_to_target"] =
        f && s && f->iteration > 0 && fmart.iteration_seconds_until(f->iteration) > 0
            ? json_number(smart.iteration_seconds_until(s->iteration) / fmart.iteration_seconds_until(f->iteration))
            : nlohmann::json();
    r["iteration_cost_ratio"] = fmart.mean_iteration_seconds() > 0
                                    ? json_number(smart.mean_iteration_seconds() / fmart.mean_iteration_seconds())
                                    : nlohmann::json();
    fmt::print(stderr, "{} ppp: target Q {:.3f}: FMART {} s, SMART {} s\n", ppp, target,
               f ? fmt::format("{:.3f}", f->elapsed) : std::string("never"),
               s ? fmt::format("{:.3f}", s->elapsed) : std::string("never"));
    results.push_back(std::move(r));
  }
  const nlohmann::json out = {
      {"case", args.case_name},
      {"grid", {case_grid.nx, case_grid.ny, case_grid.nz}},
      {"exposure", "A"},
      {"seed", args.seed},
      {"mlos_threshold", args.mlos_threshold},
      {"prune_fraction", args.tuning.prune_in_effect()},
      {"sigma_px", args.tuning.sigma_json()},
      {"smoothing_sigma_voxel", nlohmann::json{smoothing.x, smoothing.y, smoothing.z}},
      {"q", "windowed Q (Eq. 3.14, 64^3 windows) of the smoothed volume; time excludes the judging"},
      {"machine", machine_json()},
      {"results", results}};
  write_json(out, args.json_out);
}

}  // namespace

void add_bench_recon_race_command(CLI::App& bench) {
  auto args = std::make_shared<RaceArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "recon-race", "FMART against SMART on the same sparse machinery: Q per iteration, time to equal Q");
  cmd->add_option("--case", args->case_name, "Simulated case")->capture_default_str();
  cmd->add_option("--ppp", args->ppp, "Particle densities, e.g. --ppp 0.03,0.05,0.10")->delimiter(',');
  cmd->add_option("--fmart-iterations", args->fmart_iterations, "FMART iterations")->capture_default_str();
  cmd->add_option("--smart-iterations", args->smart_iterations, "SMART iterations")->capture_default_str();
  cmd->add_option("--fmart-relaxation", args->fmart_relaxation, "FMART mu in (0, 2]")->capture_default_str();
  cmd->add_option("--smart-relaxation", args->smart_relaxation, "SMART mu in (0, 2]")->capture_default_str();
  cmd->add_option("--mlos-threshold", args->mlos_threshold, "MLOS empty-pixel fraction of the image maximum")
      ->capture_default_str();
  args->tuning.add_options(*cmd);
  cmd->add_option("--q-target", args->q_target,
                  "Windowed Q both must reach (0: the lower of the two algorithms' best Q at each density)")
      ->capture_default_str();
  cmd->add_option("--smooth", args->smoothing,
                  "Gaussian sigma x,y,z (voxel) applied to both volumes before judging, as the thesis did for "
                  "FMART; 0: none")
      ->capture_default_str();
  cli::add_deprecated_option(*cmd, "--smoothing", args->smoothing, "--smooth");
  cmd->add_option("--grid", args->grid, "Override the case's grid: nx,ny,nz,voxel_mm[,cx,cy,cz]");
  cmd->add_option("--seed", args->seed, "Random seed of the particle field")->capture_default_str();
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: all cores)")->capture_default_str();
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json); --json alone, '-' or none: stdout")
      ->expected(0, 1);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
