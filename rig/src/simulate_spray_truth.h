#pragma once
// The spray-thesis session pieces shared by `tomorig simulate --case spray-thesis` (whole
// sessions, simulate_spray.cpp) and the live simulated rig (simulate_spray_scene.cpp).
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "tomorig/simulators/spray.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

// Each camera's optics: id, yaw, M, f#, pitch, noise, threshold, and its chi(z) truth.
nlohmann::json spray_cameras_json(const sim::SprayCase& c);
// The truth's flow_parameters without per-set records: the options that regenerate every
// set's droplets (sim::spray_droplets(case, trigger index): sizes, in truth-set order), the
// cameras' optics and the optics set-up TOML.
nlohmann::json spray_parameters_json(const sim::SprayCase& c);
storage::SessionTruth spray_truth(const sim::SprayCase& c, const std::string& flow_name, const nlohmann::json& parameters);
// The writer of a spray session: the case's cameras (Mono16), `comment` as the rig text.
storage::SessionWriter open_spray_writer(const std::filesystem::path& out, const sim::SprayCase& c,
                                         storage::Compression compression, bool overwrite, const std::string& comment);

}  // namespace tomorig::rig
