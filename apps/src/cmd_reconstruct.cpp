// tomorig reconstruct: one set of a session -> a volume file (HDF5 + XDMF) per exposure
// (pipeline/set_volumes.h); with --mean the mean intensity volume over --sets (spray statistics,
// pipeline/mean_volume.h). This file parses the options and prints the report.
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/mean_volume.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/pipeline/set_volumes.h"
#include "tomorig/storage/volume_file.h"

namespace tomorig::app {

using pipeline::to_json;

namespace {

struct ReconstructArgs {
  std::string session;
  std::string calib;
  std::uint64_t set = 0;
  std::string exposure = "both";
  // Width of the voxel-to-pixel weights (sigma_px): narrower than the particle images (0.75 px),
  // as wider weights blur the reconstructed blobs (Q 0.95 -> 0.87 on the reduced case,
  // docs/reconstruction.md).
  pipeline::ReconstructionChoices recon{.algorithm_from_rig = true};
  std::string out;
  bool overwrite = false;
  JsonOutput json;
  std::string png;  // intensity-versus-depth plot
  bool sparse_only = false;
  std::vector<double> smooth;  // sigma x, y, z in voxels; empty: none
  std::string chain;           // preprocessing preset or chain TOML; empty: none
  bool mean = false;           // the mean intensity volume over `sets`
  std::string sets;
  std::string slices;          // --mean: folder for the PNG slices
  CLI::Option* set_opt = nullptr;
};

std::vector<Exposure> exposures_of(const std::string& name) {
  if (name == "a" || name == "A") return {Exposure::A};
  if (name == "b" || name == "B") return {Exposure::B};
  return {Exposure::A, Exposure::B};
}

// The options one set's volumes and the mean volume share, from the command line.
template <class Options>
Options shared_options(const ReconstructArgs& args) {
  Options o;
  o.session = args.session;
  o.calib = args.calib;
  o.chain = args.chain;
  o.recon = args.recon;
  o.exposures = exposures_of(args.exposure);
  o.smooth = args.smooth;
  o.out = args.out;
  o.sparse_only = args.sparse_only;
  o.overwrite = args.overwrite;
  return o;
}

void run_mean(const ReconstructArgs& args) {
  if (args.set_opt->count()) throw bad_input("--mean averages the sets of --sets (default all): --set does not apply");
  if (!args.png.empty()) throw bad_input("--png draws one set's depth profile; with --mean use --slices FOLDER");
  auto o = shared_options<pipeline::MeanVolumeOptions>(args);
  o.sets = args.sets;
  o.slices = args.slices;
  const pipeline::MeanVolumeReport r = pipeline::write_mean_volume(o, [](int done, int total) {
    fmt::print(stderr, "mean: volume {}/{} reconstructed\n", done, total);
  });
  nlohmann::json summary = json_summary("reconstruct");
  summary.update(nlohmann::json{{"out", args.out},
                                {"xdmf", storage::VolumeFileWriter::sidecar_path(args.out).string()},
                                {"session", args.session},
                                {"mean", to_json(r)}});
  emit_json(args.json, summary);
  if (args.json.to_stdout()) return;
  const quality::IntensityMoments& m = r.moments;
  fmt::print("wrote {} and {}: mean of {} volumes ({} sets), {}\n", args.out,
             storage::VolumeFileWriter::sidecar_path(args.out).string(), r.volumes, r.sets.size(), r.algorithm);
  fmt::print("intensity centroid ({:.2f}, {:.2f}, {:.2f}) mm; 90 % of it in x {:.2f}..{:.2f}, y {:.2f}..{:.2f}, "
             "z {:.2f}..{:.2f} mm\n",
             m.centroid_mm.x, m.centroid_mm.y, m.centroid_mm.z, m.low_mm.x, m.high_mm.x, m.low_mm.y, m.high_mm.y,
             m.low_mm.z, m.high_mm.z);
  if (!r.slice_files.empty())
    fmt::print("slices: {} PNG in {}\n", r.slice_files.size(), args.slices);
}

void run(const ReconstructArgs& args) {
  cli::require_session(args.session, "reconstruct");
  if (args.mean) return run_mean(args);
  if (!args.sets.empty() || !args.slices.empty())
    throw bad_input("--sets and --slices belong to --mean (the mean intensity volume over sets); one set is --set K");
  auto o = shared_options<pipeline::SetVolumesOptions>(args);
  o.set = args.set;
  o.png = args.png;
  const pipeline::SetVolumesReport r =
      pipeline::write_set_volumes(o, {.warning = [](const std::string& text) { spdlog::warn("{}", text); },
                                      .progress = [](const std::string& text) { spdlog::info("{}", text); }});
  nlohmann::json summary = json_summary("reconstruct");
  summary.update(nlohmann::json{{"out", args.out},
                                {"xdmf", r.xdmf.string()},
                                {"session", args.session},
                                {"set", args.set},
                                {"volumes", r.volumes}});
  emit_json(args.json, summary);
  if (!args.json.to_stdout())
    fmt::print("wrote {} and {} ({} volume{})\n", args.out, r.xdmf.string(), r.volumes.size(),
               r.volumes.size() == 1 ? "" : "s");
}

}  // namespace

void add_reconstruct_command(CLI::App& root) {
  auto args = std::make_shared<ReconstructArgs>();
  CLI::App* cmd = root.add_subcommand("reconstruct", "Reconstruct the particle volume of one set of a session");
  cli::add_session_argument(*cmd, args->session, "Session file (.h5)");
  cmd->add_option("--calib", args->calib,
                  "Calibration file (TOML, from tomorig calibrate), or 'truth' for a simulated session's exact cameras "
                  "(default: the truth if present, else the rig config's calibration file)");
  args->set_opt = cmd->add_option("--set", args->set, "Set index, 0-based")->capture_default_str();
  cmd->add_option("--chain", args->chain,
                  "Preprocessing before the reconstruction: a preset (e.g. shadow-a, shadow-b) or a chain TOML");
  cmd->add_flag("--mean", args->mean,
                "Write the mean intensity volume over --sets (spray statistics, docs/spray.md) instead of one set");
  cmd->add_option("--sets", args->sets, "--mean: sets to average (N, A:B or a list); default all");
  cmd->add_option("--slices", args->slices,
                  "--mean: folder for PNG slices of the mean (through its centroid, and 5 over the depth)");
  cmd->add_option("--exposure", args->exposure, "a, b or both")
      ->check(CLI::IsMember({"a", "b", "both", "A", "B"}))
      ->capture_default_str();
  pipeline::add_reconstruction_flags(*cmd, args->recon, "the rig config's, else " + args->recon.options.algorithm);
  cmd->add_option("--threads", args->recon.options.threads, "OpenMP threads (0: all cores)")->capture_default_str();
  cmd->add_option("-o,--out", args->out, "Volume file to write (.h5; an .xdmf sidecar is written beside it)")
      ->required();
  cmd->add_option("--smooth", args->smooth,
                  "Gaussian post-smoothing sigma x,y,z in voxels, e.g. 0.68,0.68,0.1 as the thesis applied to FMART")
      ->delimiter(',')
      ->expected(3);
  cmd->add_flag("--overwrite", args->overwrite, "Replace existing output files");
  cmd->add_option("--png", args->png,
                  "Also write intensity against depth (mean per voxel of each z-slice, one curve per exposure) as a "
                  "PNG plot");
  cmd->add_flag("--sparse-only", args->sparse_only, "Store only the sparse voxel list (no dense export for ParaView)");
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
