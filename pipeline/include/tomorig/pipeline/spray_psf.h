#pragma once
// The reconstruction's depth-varying PSF from a spray optics set-up (`--psf`, issue 20): the
// PSF half-width chi(z) per camera in object um, as `tomorig optics psf --setup-out` writes it
// (measured on edge targets) or as a simulated spray session's truth holds it, turned into the
// weight sigma in pixels of each camera at each sampled depth.
#include <string>
#include <vector>

#include "tomorig/core/volume.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/optics/visibility.h"
#include "tomorig/processing/reconstruction/psf_model.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {

// `psf`: "truth" (the optics set-up of a simulated spray session's truth, optics_setup_toml) or
// an optics set-up file (TOML, docs/spray.md). Throws tomorig::Error (bad_input) naming the
// option and what to give instead.
optics::VisibilitySetup spray_optics_setup(const std::string& psf, const std::optional<storage::SessionTruth>& truth);

// One PsfModel per session camera, matched to the set-up's cameras by id: at each chi sample,
// sigma = chi / 2 (the Gaussian of Eq. 6.1) divided by the camera's object pixel at that depth
// (from its model, at the grid's centre in x and y, along world y). Throws bad_input if a
// camera has no entry in the set-up or a sigma leaves (0, 10] px.
std::vector<recon::PsfModel> psf_from_optics_setup(const optics::VisibilitySetup& setup,
                                                   const std::vector<storage::SessionCamera>& cameras,
                                                   const std::vector<const calibration::CameraModel*>& models,
                                                   const VoxelGrid& grid);

}  // namespace tomorig::pipeline
