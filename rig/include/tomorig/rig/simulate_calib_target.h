#pragma once
// `tomorig simulate --case calib-thesis`: the chessboard calibration case written as a session.
// Layout (docs/simulator.md, "calib-thesis"): one set per traverse plane, set k = plane k in
// ascending nominal z; each camera's target image is exposure A (exposure B is recorded as
// missing). The truth: /truth/cameras holds each camera's pinhole part; the truth's
// flow_name is "traverse" and flow_parameters (JSON) holds the board, each plane's nominal z
// and true offset (um, raw: not zero-mean), and each camera's radial distortion k1.
#include <cstdint>
#include <filesystem>
#include <string>

#include "tomorig/simulators/calibration_target.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

// The truth JSON (flow_parameters) of a case.
std::string calib_target_truth_json(const sim::CalibTargetCase& c);

// Renders every (camera, plane) view and writes the session; returns a one-line summary.
// Throws tomorig::Error (bad_input) if the file exists and `overwrite` is false.
std::string write_calib_target_session(const sim::CalibTargetOptions& options, const std::filesystem::path& out,
                                       storage::Compression compression, bool overwrite);

}  // namespace tomorig::rig
