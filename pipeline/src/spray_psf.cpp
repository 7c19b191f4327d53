#include "tomorig/pipeline/spray_psf.h"

#include <cmath>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/optics_setup.h"

namespace tomorig::pipeline {

optics::VisibilitySetup spray_optics_setup(const std::string& psf, const std::optional<storage::SessionTruth>& truth) {
  if (psf != "truth") return optics::read_optics_setup(psf);
  if (!truth)
    throw bad_input("--psf truth: the session holds no simulator truth; give an optics set-up file (from 'tomorig "
                    "optics psf --setup-out')");
  const nlohmann::json p = nlohmann::json::parse(truth->flow_parameters, nullptr, false);
  if (p.is_discarded() || !p.is_object() || !p.contains("optics_setup_toml") || !p["optics_setup_toml"].is_string())
    throw bad_input(fmt::format("--psf truth: the session's truth (case '{}') holds no optics set-up (only spray-thesis "
                                "sessions do); give an optics set-up file",
                                truth->case_name));
  return optics::parse_optics_setup(p["optics_setup_toml"].get<std::string>(), "the session truth's optics set-up");
}

std::vector<recon::PsfModel> psf_from_optics_setup(const optics::VisibilitySetup& setup,
                                                   const std::vector<storage::SessionCamera>& cameras,
                                                   const std::vector<const calibration::CameraModel*>& models,
                                                   const VoxelGrid& grid) {
  std::vector<recon::PsfModel> out;
  const double cx = grid.origin.x + 0.5 * (grid.nx - 1) * grid.voxel_size;
  const double cy = grid.origin.y + 0.5 * (grid.ny - 1) * grid.voxel_size;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const optics::CameraOptics* optics_cam = nullptr;
    for (const optics::CameraOptics& o : setup.cameras)
      if (o.id == cameras[c].id) optics_cam = &o;
    if (optics_cam == nullptr)
      throw bad_input(fmt::format("--psf: the optics set-up has no camera '{}' (the session's camera {}); its cameras' "
                                  "ids must be the session's",
                                  cameras[c].id, c));
    recon::PsfModel model;
    for (const optics::ChiSample& s : optics_cam->chi) {
      // Pixels per mm across the line of sight: world y is perpendicular to every yawed view.
      constexpr double kStepMm = 0.5;
      const Vec2d p0 = models[c]->project({cx, cy - kStepMm, s.z_mm});
      const Vec2d p1 = models[c]->project({cx, cy + kStepMm, s.z_mm});
      const double px_per_mm = std::hypot(p1.x - p0.x, p1.y - p0.y) / (2 * kStepMm);
      const double sigma = 0.5 * s.chi_um * 1e-3 * px_per_mm;
      model.samples.push_back({s.z_mm, sigma, sigma});
    }
    model.validate(fmt::format("--psf: camera '{}'", cameras[c].id));
    out.push_back(std::move(model));
  }
  return out;
}

}  // namespace tomorig::pipeline
