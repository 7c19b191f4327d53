#pragma once
// What a reconstruction needs from a recording besides its pixels: the camera models, in the
// session's camera order, and the voxel grid. Shared by `reconstruct`, `selfcal`, `bench
// recon`, the back-end (run_backend) and the back-end stage of a live rig.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/config/rig_config.h"

#include "tomorig/core/volume.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/storage/session_file.h"

namespace CLI {
class App;
}

namespace tomorig::pipeline {

// A recording as a reconstruction sees it, a session file or a live rig alike: its cameras,
// its rig configuration (parsed once, here) and, when simulated, the truth.
struct SessionDescription {
  std::string name;  // the session path, or the live rig, for messages
  std::vector<storage::SessionCamera> cameras;
  std::optional<storage::SessionTruth> truth;
  std::string rig_toml;                  // as stored; empty: the recording holds no rig config
  std::optional<config::RigConfig> rig;  // parsed rig_toml; nullopt if empty or invalid
  std::string rig_error;                 // why rig_toml did not parse (raised only when the rig is needed)
  // Where stages may store per-set quick-look numbers with the recording (the live session
  // file being written), or empty: the recording keeps none (a session read back, a replay).
  // Callable from a stage's own threads, until the stage's end() returns.
  std::function<void(const storage::QuickLookRecord&)> store_quicklook;

  // The rig config, or nullptr if the recording holds none; throws the parse error (bad_input)
  // if it holds an invalid one.
  const config::RigConfig* rig_config() const;
};

// Reads `session`'s cameras, truth and rig config.
SessionDescription describe_session(const storage::SessionReader& session);
// A live or replayed recording: `rig_toml` is parsed here; `name` is used in messages.
SessionDescription describe_recording(std::string name, std::vector<storage::SessionCamera> cameras,
                                      std::string rig_toml, std::optional<storage::SessionTruth> truth);

struct SessionCameras {
  std::vector<std::shared_ptr<const calibration::CameraModel>> models;  // session camera order
  std::string source;  // "truth of <session>" or the calibration file, for reports
  // A loaded calibration whose fit left more than kCalibrationWarnRmsPx: what the commands
  // using these cameras repeat to their user (the calibration's own warning).
  std::vector<std::string> warnings;
  std::vector<const calibration::CameraModel*> pointers() const;
};

// The simulator's exact cameras stored in the session's /truth. Throws tomorig::Error
// (bad_input) if the session has no truth (then a calibration file is needed) or its truth
// cameras do not match the session's cameras by id and size.
SessionCameras truth_cameras(const SessionDescription& session);

// The models of a calibration file (docs/calibration.md): its camera i is the session's camera
// i. Throws tomorig::Error (bad_input) if the file is bad, or its camera count or image sizes
// disagree with the session's, naming the camera.
SessionCameras calibration_cameras(const SessionDescription& session, const std::filesystem::path& file);

// `calib` empty or "truth": truth_cameras (empty falls back to the rig config's calibration
// file when the session has no truth); otherwise calibration_cameras.
SessionCameras session_cameras(const SessionDescription& session, const std::string& calib);

// The [grid] of the session's rig config, as a VoxelGrid (the config gives the grid centre;
// VoxelGrid wants the centre of voxel (0, 0, 0)).
VoxelGrid grid_from_session(const SessionDescription& session);

// "nx,ny,nz,voxel_mm" or "nx,ny,nz,voxel_mm,cx,cy,cz" (cx..cz: grid centre, mm; default 0).
// Throws tomorig::Error (bad_input) quoting `text` and the expected form.
VoxelGrid parse_grid(const std::string& text);

// The command-line side of a reconstruction set-up (`reconstruct`, `process`, the backend
// stage). Every setting has one default, the library's: `options` starts as
// recon::ReconstructionOptions{} and the flags bind to its fields.
struct ReconstructionChoices {
  recon::ReconstructionOptions options;  // relaxation, mlos_threshold, prune_fraction, threads, ...
  // Named on the command line; empty: the recording's rig config names it if
  // `algorithm_from_rig` (`reconstruct`), else options.algorithm (`process`: the rig's choice is
  // ignored, as issue 5 asks).
  std::string algorithm;
  bool algorithm_from_rig = true;
  int iterations = 0;  // named on the command line; 0: the rig config's, else options.max_iterations
  std::string grid;    // empty: the rig config's [grid]; else as parse_grid
  double sigma_px = recon::kDefaultPsfSigmaPx;  // weight (PSF) sigma of every camera, pixels
  // Empty: sigma_px everywhere. Else each camera's PSF over depth, replacing sigma_px: a PSF
  // file (`tomorig optics psf --psf-out`, sigma_px per depth), an optics set-up file (chi(z)
  // per camera, `tomorig optics psf --setup-out`) or "truth" (a simulated spray session's).
  std::string psf;
};

// Registers --algorithm, --iterations, --relaxation, --mlos-threshold, --grid, --sigma-px and --psf,
// bound to `choices` (defaults shown from the library's options). `algorithm_default` says in
// the help what an absent --algorithm means.
void add_reconstruction_flags(CLI::App& cmd, ReconstructionChoices& choices, const std::string& algorithm_default);

// Validated options and an input holding the cameras, grid, PSF and sensor sizes (images left
// to the caller), from the session's rig config and `choices`. Throws tomorig::Error (bad_input)
// naming the option that is wrong.
struct ReconstructionSetup {
  recon::ReconstructionOptions options;
  recon::ReconstructionInput input;
};
ReconstructionSetup reconstruction_setup(const SessionDescription& session, const SessionCameras& cameras,
                                         const ReconstructionChoices& choices);

}  // namespace tomorig::pipeline
