#pragma once
// Volume self-calibration (thesis Sect. 2.2, Wieneke 2008) of a session's calibration with its
// own particle images: the snapshots (sets x exposures) are read from the session, the
// calibration corrected by calibration::self_calibrate, and, for a simulated session, both
// calibrations compared with the true cameras. `tomorig selfcal` prints the report.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/self_calibration.h"

namespace tomorig::pipeline {

struct SessionSelfcalOptions {
  std::string calib;  // as session_cameras: "truth", a calibration file, or empty
  std::vector<std::uint64_t> sets;  // empty: the first `default_sets` sets
  std::uint64_t default_sets = 10;
  bool use_a = true, use_b = true;  // exposures to use
  // The volume to calibrate; nullopt: the voxel grid `grid` (as parse_grid; empty: the rig
  // config's [grid]) edge to edge.
  std::optional<calibration::VolumeBounds> volume;
  std::string grid;
  // Tests: misalign one camera of the input first (about its image centre).
  struct Perturbation {
    std::size_t camera = 0;
    double du_px = 0, dv_px = 0, rotation_deg = 0;
  };
  std::optional<Perturbation> perturb;
  // The algorithm's settings, with its defaults; camera names and require_convergence are set
  // by selfcal_session (the report is made either way).
  calibration::SelfCalibrationOptions selfcal;
};

struct SessionSelfcalReport {
  calibration::SelfCalibrationResult result;
  std::string cameras_source;  // where the input calibration came from
  std::vector<std::uint64_t> sets;
  std::size_t snapshots = 0;
  calibration::VolumeBounds bounds;
  std::vector<std::string> camera_names;
  // Mean |model - true camera| projection of the true particles, px (simulated sessions only).
  std::vector<std::optional<double>> truth_before, truth_after;
  // The corrected calibration, ready for calibration::save_calibration (converged or not).
  std::vector<calibration::CameraCalibration> calibration;
  // Cameras still above tolerance, "camera 1 (cam1): mean disparity 0.081 px; ..." (empty if converged).
  std::string not_converged;
};

// Throws tomorig::Error (bad_input) naming the option for a bad session, set, volume or
// setting. `notice` gets progress and warnings (a snapshot skipped for a missing frame).
SessionSelfcalReport selfcal_session(const std::filesystem::path& session, SessionSelfcalOptions options,
                                     const std::function<void(const std::string&)>& notice = {});

}  // namespace tomorig::pipeline
