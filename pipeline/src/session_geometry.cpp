#include "tomorig/pipeline/session_geometry.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/optics/psf_table.h"
#include "tomorig/pipeline/spray_psf.h"

namespace tomorig::pipeline {
namespace {

VoxelGrid centred_grid(int nx, int ny, int nz, double voxel_mm, const Vec3d& centre) {
  VoxelGrid g = VoxelGrid::centred(nx, ny, nz, voxel_mm);
  g.origin = {g.origin.x + centre.x, g.origin.y + centre.y, g.origin.z + centre.z};
  return g;
}

}  // namespace

const config::RigConfig* SessionDescription::rig_config() const {
  if (rig_toml.empty()) return nullptr;
  if (!rig) throw bad_input(rig_error);
  return &*rig;
}

SessionDescription describe_recording(std::string name, std::vector<storage::SessionCamera> cameras,
                                      std::string rig_toml, std::optional<storage::SessionTruth> truth) {
  SessionDescription d;
  d.name = std::move(name);
  d.cameras = std::move(cameras);
  d.truth = std::move(truth);
  d.rig_toml = std::move(rig_toml);
  if (!d.rig_toml.empty()) {
    try {
      d.rig = config::parse_rig_config(d.rig_toml, d.name + ":/config");
    } catch (const Error& e) {
      d.rig_error = e.what();
    }
  }
  return d;
}

SessionDescription describe_session(const storage::SessionReader& session) {
  return describe_recording(session.path().string(), session.info().cameras, session.info().rig_config_toml,
                            session.has_truth() ? std::optional(session.truth()) : std::nullopt);
}

std::vector<const calibration::CameraModel*> SessionCameras::pointers() const {
  std::vector<const calibration::CameraModel*> out;
  for (const auto& m : models) out.push_back(m.get());
  return out;
}

SessionCameras truth_cameras(const SessionDescription& session) {
  const std::string& file = session.name;
  if (!session.truth)
    throw bad_input(fmt::format("session '{}' is not simulated, so it has no truth cameras; give a calibration "
                                "file with --calib",
                                file));
  const storage::SessionTruth& truth = *session.truth;
  SessionCameras out;
  out.source = "truth of " + file;
  for (const storage::SessionCamera& cam : session.cameras) {
    const storage::TruthCamera* match = nullptr;
    for (const auto& t : truth.cameras)
      if (t.id == cam.id) match = &t;
    if (match == nullptr)
      throw bad_input(fmt::format("session '{}': camera {} has no truth camera; give a calibration file with --calib",
                                  file, cam.id));
    if (match->width != cam.width || match->height != cam.height)
      throw bad_input(fmt::format("session '{}': camera {} is {} x {} but its truth camera is {} x {}", file, cam.id,
                                  cam.width, cam.height, match->width, match->height));
    if (match->model != "pinhole")
      throw bad_input(fmt::format("session '{}': truth camera {} has model '{}'; only 'pinhole' is supported", file,
                                  cam.id, match->model));
    calibration::PinholeParameters p;
    p.fx = match->K[0];
    p.cx = match->K[2];
    p.fy = match->K[4];
    p.cy = match->K[5];
    p.R = match->R;
    p.t = match->t;
    out.models.push_back(std::make_shared<calibration::PinholeCamera>(p));
  }
  return out;
}

SessionCameras calibration_cameras(const SessionDescription& session, const std::filesystem::path& file) {
  const std::vector<calibration::CameraCalibration> cal = calibration::load_calibration(file);
  const auto& cams = session.cameras;
  if (cal.size() != cams.size())
    throw bad_input(fmt::format("calibration file '{}' has {} cameras but session '{}' has {}; use the calibration "
                                "of this rig",
                                file.string(), cal.size(), session.name, cams.size()));
  SessionCameras out;
  out.source = file.string();
  out.models.resize(cams.size());
  for (const auto& c : cal) {
    if (c.id < 0 || static_cast<std::size_t>(c.id) >= cams.size() || out.models[static_cast<std::size_t>(c.id)])
      throw bad_input(fmt::format("calibration file '{}': camera {} is not one of cameras 0 to {} of the session, or "
                                  "appears twice",
                                  file.string(), c.id, cams.size() - 1));
    const auto& cam = cams[static_cast<std::size_t>(c.id)];
    if (c.image_size.width != cam.width || c.image_size.height != cam.height)
      throw bad_input(fmt::format("calibration file '{}': camera {} was calibrated on {} x {} images but session "
                                  "camera {} is {} x {}",
                                  file.string(), c.id, c.image_size.width, c.image_size.height, cam.id, cam.width,
                                  cam.height));
    out.models[static_cast<std::size_t>(c.id)] = c.model;
    if (const std::string warning = calibration::rms_warning(c); !warning.empty())
      out.warnings.push_back(fmt::format("calibration file '{}': {}", file.string(), warning));
  }
  return out;
}

SessionCameras session_cameras(const SessionDescription& session, const std::string& calib) {
  if (calib == "truth") return truth_cameras(session);
  if (!calib.empty()) return calibration_cameras(session, calib);
  if (session.truth) return truth_cameras(session);
  if (const config::RigConfig* rig = session.rig_config(); rig != nullptr && rig->calibration_file)
    return calibration_cameras(session, *rig->calibration_file);
  throw bad_input(fmt::format("session '{}' has neither truth cameras nor a calibration file in its rig config; give "
                              "one with --calib",
                              session.name));
}

VoxelGrid grid_from_session(const SessionDescription& session) {
  const config::RigConfig* rig = session.rig_config();
  if (rig == nullptr)
    throw bad_input(fmt::format("session '{}' holds no rig config, so no voxel grid; give one with --grid",
                                session.name));
  const config::GridConfig& g = rig->grid;
  return centred_grid(g.nx, g.ny, g.nz, g.voxel_size_mm, {g.origin_mm[0], g.origin_mm[1], g.origin_mm[2]});
}

VoxelGrid parse_grid(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  auto fail = [&] {
    throw bad_input(fmt::format("--grid '{}' is not valid: expected nx,ny,nz,voxel_mm or nx,ny,nz,voxel_mm,cx,cy,cz "
                                "with nx, ny, nz whole numbers > 0 and voxel_mm > 0, e.g. 512,512,160,0.0195",
                                text));
  };
  while (std::getline(in, item, ',')) {
    double v = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (ec != std::errc() || end != item.data() + item.size() || !std::isfinite(v)) fail();
    values.push_back(v);
  }
  if (values.size() != 4 && values.size() != 7) fail();
  for (int i = 0; i < 3; ++i)
    if (values[i] < 1 || values[i] != std::floor(values[i]) || values[i] > 65535) fail();
  if (!(values[3] > 0)) fail();
  const Vec3d centre = values.size() == 7 ? Vec3d{values[4], values[5], values[6]} : Vec3d{};
  return centred_grid(static_cast<int>(values[0]), static_cast<int>(values[1]), static_cast<int>(values[2]), values[3],
                      centre);
}

void add_reconstruction_flags(CLI::App& cmd, ReconstructionChoices& choices, const std::string& algorithm_default) {
  cmd.add_option("--algorithm", choices.algorithm,
                 "Reconstruction algorithm: " + recon::algorithm_names() + ", any case (default: " + algorithm_default +
                     ")")
      ->transform(CLI::Validator(  // "FMART" as well as "fmart" (issue 23)
          [](std::string& name) {
            for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            return std::string();
          },
          "", "lower case"));
  cmd.add_option("--iterations", choices.iterations,
                 fmt::format("Iterations of MART/SMART/FMART (default: the rig config's, else {})",
                             choices.options.max_iterations));
  cmd.add_option("--relaxation", choices.options.relaxation, "Relaxation mu in (0, 2]")->capture_default_str();
  cmd.add_option("--mlos-threshold", choices.options.mlos_threshold,
                 "Fraction of each image's maximum below which a pixel counts as empty for MLOS; higher is "
                 "faster with fewer ghosts, lower keeps faint particles")
      ->capture_default_str();
  cmd.add_option("--grid", choices.grid, "Voxel grid nx,ny,nz,voxel_mm[,cx,cy,cz] (default: the rig config's [grid])");
  cmd.add_option("--sigma-px", choices.sigma_px,
                 "Gaussian sigma of the voxel-to-pixel weights (PSF), pixels, all cameras")
      ->capture_default_str();
  cmd.add_option("--psf", choices.psf,
                 "Depth-varying PSF per camera instead of --sigma-px: a PSF file ('tomorig optics psf --psf-out'), "
                 "an optics set-up file ('tomorig optics psf --setup-out') or 'truth' (a simulated spray session's); "
                 "docs/spray.md");
}

namespace {

// A PSF file holds the reconstruction's sigma itself (sigma_px per depth); an optics set-up
// file holds chi(z), which spray_psf.h turns into sigma. "truth" is neither.
bool is_psf_file(const std::string& psf) { return psf != "truth" && optics::is_psf_table_file(psf); }

// Each session camera's depth-varying PSF from a PSF file, matched by camera id.
std::vector<recon::PsfModel> measured_psf(const SessionDescription& session, const std::string& file) {
  const optics::PsfTable table = optics::read_psf_table(file);
  std::vector<recon::PsfModel> out;
  for (const storage::SessionCamera& c : session.cameras) {
    const optics::PsfTableCamera* cam = table.find(c.id);
    if (cam == nullptr) {
      std::string ids;
      for (const optics::PsfTableCamera& t : table.cameras) ids += (ids.empty() ? "" : ", ") + t.id;
      throw bad_input(fmt::format("--psf {}: no PSF for camera '{}' of {} (the file has {}): measure it with `tomorig "
                                  "optics psf` on this rig's calibration images",
                                  file, c.id, session.name, ids));
    }
    recon::PsfModel model;
    for (std::size_t k = 0; k < cam->z_mm.size(); ++k)
      model.samples.push_back({cam->z_mm[k], cam->sigma_px[k], cam->sigma_px[k]});
    model.validate(fmt::format("--psf {}: camera '{}'", file, c.id));
    out.push_back(std::move(model));
  }
  return out;
}

}  // namespace

ReconstructionSetup reconstruction_setup(const SessionDescription& session, const SessionCameras& cameras,
                                         const ReconstructionChoices& choices) {
  ReconstructionSetup setup;
  recon::ReconstructionOptions& options = setup.options;
  options = choices.options;
  const config::RigConfig* rig = session.rig_config();
  if (!choices.algorithm.empty())
    options.algorithm = choices.algorithm;
  else if (choices.algorithm_from_rig && rig != nullptr && !rig->processing.algorithm.empty())
    options.algorithm = rig->processing.algorithm;
  if (choices.iterations > 0)
    options.max_iterations = choices.iterations;
  else if (rig != nullptr && rig->processing.iterations > 0)
    options.max_iterations = rig->processing.iterations;
  options.validate();

  recon::ReconstructionInput& input = setup.input;
  input.cameras = cameras.pointers();
  input.grid = choices.grid.empty() ? grid_from_session(session) : parse_grid(choices.grid);
  if (choices.psf.empty()) {
    input.psf.assign(input.cameras.size(), recon::PsfModel::constant(choices.sigma_px));
    if (!input.psf.empty()) input.psf.front().validate("--sigma-px");
  } else if (is_psf_file(choices.psf)) {
    input.psf = measured_psf(session, choices.psf);
  } else {
    input.psf = psf_from_optics_setup(spray_optics_setup(choices.psf, session.truth), session.cameras, input.cameras,
                                      input.grid);
  }
  for (const storage::SessionCamera& c : session.cameras) input.sensor_sizes.push_back({c.width, c.height});
  return setup;
}

}  // namespace tomorig::pipeline
