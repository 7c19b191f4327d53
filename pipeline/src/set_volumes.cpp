#include "tomorig/pipeline/set_volumes.h"

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/pipeline/exposure_images.h"
#include "tomorig/pipeline/report_json.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "tomorig/processing/quality/depth_profile_plot.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/processing/reconstruction/smoothing.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/output_path.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/volume_file.h"

namespace tomorig::pipeline {

SetVolumesReport write_set_volumes(const SetVolumesOptions& args, const SetVolumesHooks& hooks) {
  if (!args.png.empty()) storage::check_output_path(args.png, args.overwrite, "plot");  // before any work
  const storage::SessionReader session(args.session);
  if (args.set >= session.set_count())
    throw bad_input(fmt::format("--set {} is out of range: session '{}' has {} sets (0 to {})", args.set,
                                args.session.string(), session.set_count(),
                                session.set_count() == 0 ? 0 : session.set_count() - 1));
  const SessionDescription description = describe_session(session);
  const SessionCameras cameras = session_cameras(description, args.calib);
  if (hooks.warning)
    for (const std::string& warning : cameras.warnings) hooks.warning(warning);

  ReconstructionSetup setup = reconstruction_setup(description, cameras, args.recon);
  const recon::ReconstructionOptions& options = setup.options;
  const auto reconstructor = recon::make_reconstructor(options);
  recon::ReconstructionInput& input = setup.input;

  FrameSet set = session.read_set(args.set);
  SessionPreprocessor(session, args.chain).apply(set);
  nlohmann::json parameters = {{"algorithm", options.algorithm},
                               {"max_iterations", options.max_iterations},
                               {"relaxation", options.relaxation},
                               {"sigma_px", args.recon.sigma_px},
                               {"psf", args.recon.psf},
                               {"chain", args.chain},
                               {"smoothing_sigma_voxel", args.smooth},
                               {"cameras", cameras.source},
                               {"dt_ns", set.dt_ns}};
  if (!args.recon.psf.empty()) parameters["sigma_px"] = nullptr;  // each camera's sigma over depth instead
  storage::VolumeFileWriter out(args.out, {args.session.string(), args.set, parameters.dump()},
                                {.overwrite = args.overwrite, .dense_export = !args.sparse_only});
  SetVolumesReport report;
  std::vector<quality::DepthCurve> depth_curves;
  for (const Exposure e : args.exposures) {
    const std::string name = e == Exposure::A ? "a" : "b";
    input.images = exposure_images(set, e, args.session.string(), args.set,
                                   "this exposure cannot be reconstructed: choose another set");
    if (hooks.progress)
      hooks.progress(fmt::format("reconstructing set {} exposure {} with {} on a {} x {} x {} grid...", args.set,
                                 e == Exposure::A ? "A" : "B", options.algorithm, input.grid.nx, input.grid.ny,
                                 input.grid.nz));
    recon::ReconstructionReport recon_report;
    SparseVolume volume = reconstructor->reconstruct(input, recon_report);
    if (!args.smooth.empty())
      volume = recon::gaussian_smooth(volume, {args.smooth[0], args.smooth[1], args.smooth[2]},
                                      args.recon.options.threads);
    if (hooks.progress) hooks.progress("  " + recon_report.brief());
    const nlohmann::json report_json = to_json(recon_report);
    out.add(name, volume, {options.algorithm, e == Exposure::A ? "A" : "B", report_json.dump()});
    report.volumes[name] = report_json;
    if (!args.png.empty()) {
      quality::DepthCurve curve{e == Exposure::A ? "exposure A" : "exposure B", {}, quality::mean_intensity_per_slice(volume)};
      for (int k = 0; k < volume.grid.nz; ++k) curve.z_mm.push_back(volume.grid.centre_of(0, 0, k).z);
      depth_curves.push_back(std::move(curve));
    }
  }
  out.finish();
  if (!args.png.empty())
    storage::write_png(args.png.string(), quality::depth_profile_plot(
                                              depth_curves, fmt::format("set {}, {}", args.set, options.algorithm)));
  report.out = args.out;
  report.xdmf = storage::VolumeFileWriter::sidecar_path(args.out);
  return report;
}

}  // namespace tomorig::pipeline
