#include "tomorig/pipeline/volume_pair.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"
#include "tomorig/storage/output_path.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/volume_file.h"

namespace tomorig::pipeline {
namespace {

// The pulse separation `tomorig reconstruct` records in its parameters ("dt_ns"), or 0.
std::int64_t recorded_dt_ns(const storage::VolumeFileReader& file) {
  const nlohmann::json p = nlohmann::json::parse(file.info().parameters_json, nullptr, false);
  if (p.is_object() && p.contains("dt_ns") && p["dt_ns"].is_number()) return p["dt_ns"].get<std::int64_t>();
  return 0;
}

}  // namespace

VolumePairReport correlate_volume_pair(const VolumePairOptions& args,
                                       const std::function<void(const std::string& message)>& progress) {
  // Before anything is read: an existing results file (perhaps a whole `process` run) is never
  // replaced without --overwrite.
  storage::check_output_path(args.out, args.overwrite, "results");
  const storage::VolumeFileReader file_a(args.volumes);
  std::unique_ptr<storage::VolumeFileReader> other;
  if (!args.volume_b.empty()) other = std::make_unique<storage::VolumeFileReader>(args.volume_b);
  const storage::VolumeFileReader& file_b = other ? *other : file_a;
  // With two files and no volume of name_b in the second, its only (or first) volume.
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
  VolumePairReport report;
  report.name_b = name_b;
  if (progress)
    progress(fmt::format("correlating '{}' and '{}' ({} x {} x {} voxels)...", args.name_a, name_b, ga.nx, ga.ny, ga.nz));
  storage::SetResult result;
  result.field = piv::correlate(a, b, options, report.correlation);
  result.set_index = file_a.info().set_index;
  result.dt_ns = dt;
  result.seconds = report.correlation.seconds_total;
  result.report_json = nlohmann::json{{"correlation", to_json(report.correlation)}}.dump();

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
  report.out = args.out;
  report.xdmf = storage::ResultsWriter::sidecar_path(args.out).string();
  report.nodes[0] = result.field.nx;
  report.nodes[1] = result.field.ny;
  report.nodes[2] = result.field.nz;
  return report;
}

}  // namespace tomorig::pipeline
