// tomorig piv3d: correlate two given volumes (e.g. the two exposures `tomorig reconstruct`
// wrote, /volumes/a and /volumes/b) into a results file with one set.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/pipeline/correlation_args.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/output_path.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/volume_file.h"

namespace tomorig::app {

using pipeline::CorrelationArgs;
using pipeline::add_correlation_flags;
using pipeline::correlation_options;
using pipeline::to_json;

namespace {

struct Piv3dArgs {
  std::string volumes;
  std::string volume_b;
  std::string name_a = "a";
  std::string name_b = "b";
  std::string out;
  std::optional<double> dt_ns;  // --dt; none: the volume file's
  int threads = 0;
  bool overwrite = false;
  JsonOutput json;
  CorrelationArgs correlation;
};

// The pulse separation `tomorig reconstruct` records in its parameters ("dt_ns"), or 0.
std::int64_t recorded_dt_ns(const storage::VolumeFileReader& file) {
  const nlohmann::json p = nlohmann::json::parse(file.info().parameters_json, nullptr, false);
  if (p.is_object() && p.contains("dt_ns") && p["dt_ns"].is_number()) return p["dt_ns"].get<std::int64_t>();
  return 0;
}

void run(const Piv3dArgs& args) {
  // Before anything is read: an existing results file (perhaps a whole `process` run) is never
  // replaced without --overwrite.
  storage::check_output_path(args.out, args.overwrite, "results");
  const storage::VolumeFileReader file_a(args.volumes);
  std::unique_ptr<storage::VolumeFileReader> other;
  if (!args.volume_b.empty()) other = std::make_unique<storage::VolumeFileReader>(args.volume_b);
  const storage::VolumeFileReader& file_b = other ? *other : file_a;
  // With two files and no --b, the second file's only (or first) volume.
  std::string name_b = args.name_b;
  if (other && !file_b.volumes().empty() &&
      std::none_of(file_b.volumes().begin(), file_b.volumes().end(),
                   [&](const storage::StoredVolume& v) { return v.name == name_b; }))
    name_b = file_b.volumes().front().name;
  const storage::StoredVolume& meta_a = file_a.volume(args.name_a);
  const storage::StoredVolume& meta_b = file_b.volume(name_b);
  const VoxelGrid& ga = meta_a.grid;
  const VoxelGrid& gb = meta_b.grid;
  if (ga.nx != gb.nx || ga.ny != gb.ny || ga.nz != gb.nz || std::abs(ga.voxel_size - gb.voxel_size) > 1e-9 * ga.voxel_size ||
      std::abs(ga.origin.x - gb.origin.x) + std::abs(ga.origin.y - gb.origin.y) + std::abs(ga.origin.z - gb.origin.z) >
          1e-6 * ga.voxel_size)
    throw bad_input(fmt::format("volumes '{}' ({} x {} x {}, {} mm voxels) and '{}' ({} x {} x {}, {} mm voxels) lie "
                                "on different grids; reconstruct both exposures on the same --grid",
                                args.name_a, ga.nx, ga.ny, ga.nz, ga.voxel_size, name_b, gb.nx, gb.ny, gb.nz,
                                gb.voxel_size));

  std::int64_t dt = static_cast<std::int64_t>(std::llround(args.dt_ns.value_or(0.0)));
  if (dt < 0) throw bad_input(fmt::format("--dt {}ns must be > 0", dt));
  if (dt == 0) dt = recorded_dt_ns(file_a);
  if (dt <= 0)
    throw bad_input(fmt::format("volume file '{}' records no pulse separation (dt = 0 or missing), so velocities "
                                "cannot be computed; give it with --dt (e.g. --dt 80us)",
                                args.volumes));

  CorrelationArgs corr_args = args.correlation;
  corr_args.threads = args.threads;
  const piv::CorrelationOptions options = correlation_options(corr_args);
  options.validate(ga);  // interrogation volumes larger than the volume: refused before reading voxels

  const SparseVolume a = file_a.read_sparse(args.name_a);
  const SparseVolume b = file_b.read_sparse(name_b);
  piv::CorrelationReport report;
  fmt::print(stderr, "correlating '{}' and '{}' ({} x {} x {} voxels)...\n", args.name_a, name_b, ga.nx, ga.ny, ga.nz);
  storage::SetResult result;
  result.field = piv::correlate(a, b, options, report);
  result.set_index = file_a.info().set_index;
  result.dt_ns = dt;
  result.seconds = report.seconds_total;
  result.report_json = nlohmann::json{{"correlation", to_json(report)}}.dump();

  const nlohmann::json parameters = {{"volumes", args.volumes},
                                     {"volume_b", args.volume_b},
                                     {"names", {args.name_a, name_b}},
                                     {"correlation", to_json(options)}};
  const std::string identity =
      fmt::format("volumes of {}#{}", file_a.info().source_session.empty() ? args.volumes : file_a.info().source_session,
                  file_a.info().set_index);
  storage::ResultsWriter writer(args.out,
                                {.session_path = file_a.info().source_session,
                                 .session_identity = identity,
                                 .parameters_json = parameters.dump(),
                                 .voxel_size_mm = ga.voxel_size},
                                {.overwrite = args.overwrite});
  writer.add(result);
  writer.close();
  nlohmann::json summary = json_summary("piv3d");
  summary.update(nlohmann::json{{"out", args.out},
                                {"xdmf", storage::ResultsWriter::sidecar_path(args.out).string()},
                                {"nodes", {result.field.nx, result.field.ny, result.field.nz}},
                                {"correlation", to_json(report)}});
  emit_json(args.json, summary);
  if (!args.json.to_stdout())
    fmt::print("wrote {} and {}: {} vectors, {:.1f} % valid, {} replaced, {} invalid, {:.1f} s\n", args.out,
               summary["xdmf"].get<std::string>(), report.valid + report.replaced + report.invalid,
               100.0 * report.valid_fraction(), report.replaced, report.invalid, report.seconds_total);
}

}  // namespace

void add_piv3d_command(CLI::App& root) {
  auto args = std::make_shared<Piv3dArgs>();
  CLI::App* cmd = root.add_subcommand("piv3d", "Correlate two volumes (e.g. both exposures of a volume file) into a "
                                               "results file");
  cmd->add_option("--volumes", args->volumes, "Volume file (.h5, from tomorig reconstruct)")->required();
  cmd->add_option("--volume-b", args->volume_b, "Second volume file holding volume b (default: --volumes)");
  cmd->add_option("--a", args->name_a, "Name of the first volume")->capture_default_str();
  cmd->add_option("--b", args->name_b, "Name of the second volume")->capture_default_str();
  cmd->add_option("-o,--out", args->out, "Results file to write (.h5)")->required();
  cmd->add_flag("--overwrite", args->overwrite, "Replace the results file if it exists");
  cli::add_dt_option(*cmd, args->dt_ns, "Pulse separation (default: the one recorded in the volume file)");
  add_correlation_flags(*cmd, args->correlation);
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: all cores)")->capture_default_str();
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
