// Residual tables of `tomorig calibrate`; see calibrate_report.h.
#include "calibrate_report.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"

namespace tomorig::app {

void print_report(const std::vector<ModelResult>& results, const std::string& stored, const std::string& out) {
  fmt::print("{:>6}  {:<10} {:>7} {:>6} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}\n", "camera", "model", "points",
             "planes", "fwd RMS px", "mean px", "max px", "rev RMS um", "mean um", "max um", "converged");
  for (const ModelResult& r : results) {
    if (!r.error.empty()) {
      fmt::print("{:>6}  {:<10} {}\n", r.camera, r.report.model, "refused or failed: " + r.error);
      continue;
    }
    const auto& p = r.report;
    fmt::print("{:>6}  {:<10} {:>7} {:>6} {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g} {:>10}\n", r.camera,
               p.model, p.points, p.planes, p.forward_rms_px, p.forward_mean_px, p.forward_max_px, p.reverse_rms_um,
               p.reverse_mean_um, p.reverse_max_um, p.converged ? (p.retry.empty() ? "yes" : "yes, retry") : "no");
  }
  fmt::print("(forward: image distance between each point and its projection; reverse: world distance between each "
             "point and the back-projection of its pixel onto its plane, i.e. at the target)\n");
  fmt::print("\nper plane:\n{:>6}  {:<10} {:>10} {:>7} {:>12} {:>12}\n", "camera", "model", "z mm", "points",
             "forward px", "reverse um");
  for (const ModelResult& r : results)
    for (const PlaneResidual& p : r.planes)
      fmt::print("{:>6}  {:<10} {:>10.4g} {:>7} {:>12.4g} {:>12.4g}\n", r.camera, r.report.model, p.z_mm, p.points,
                 p.forward_px, p.reverse_um);
  if (out.empty() && !stored.empty())
    fmt::print("nothing written\n");
  else if (!out.empty())
    fmt::print("wrote {} (model {} for every camera)\n", out, stored);
}

void print_cross_validation(const std::vector<CrossValidation>& results) {
  const bool by_point = !results.empty() && results.front().left_out == LeaveOut::point;
  fmt::print("\ncross-validation (each {} left out in turn, the model fitted to the others):\n{:>6}  {:<18} {:>6} "
             "{:>7} {:>10} {:>10}\n",
             by_point ? "point" : "plane", "camera", "model", "folds", "points", "RMS px", "max px");
  for (const CrossValidation& cv : results) {
    if (!cv.error.empty())
      fmt::print("{:>6}  {:<18} refused or failed: {}\n", cv.camera, cv.model, cv.error);
    else
      fmt::print("{:>6}  {:<18} {:>6} {:>7} {:>10.4g} {:>10.4g}\n", cv.camera, cv.model, cv.folds, cv.points, cv.rms_px,
                 cv.max_px);
  }
}

nlohmann::json cross_validation_json(const std::vector<CrossValidation>& results) {
  nlohmann::json list = nlohmann::json::array();
  for (const CrossValidation& cv : results) {
    nlohmann::json j{{"camera", cv.camera},
                     {"model", cv.model},
                     {"left_out", cv.left_out == LeaveOut::point ? "point" : "plane"},
                     {"folds", cv.folds},
                     {"points", cv.points}};
    if (!cv.error.empty()) j["error"] = cv.error;
    else j["rms_px"] = cv.rms_px, j["max_px"] = cv.max_px;
    list.push_back(j);
  }
  return list;
}

void print_stage_offsets(const StageOffsets& s) {
  fmt::print("traverse correction (thesis Sect. 6.3.3): {} cycles, {}; plane offsets in um (gauge: zero mean, no "
             "linear trend over z in x and z)\n",
             s.cycles, s.converged ? "converged" : "NOT converged");
  fmt::print("{:>8}  {:<8} {:>9} {:>9} {:>9}\n", "z mm", "from", "dx um", "dy um", "dz um");
  for (std::size_t k = 0; k < s.plane_z_mm.size(); ++k) {
    const Vec3d& o = s.offsets_mm[k];
    fmt::print("{:>8.4g}  {:<8} {:>9.3f} {:>9.3f} {:>9.3f}\n", s.plane_z_mm[k], "all", o.x * 1e3, o.y * 1e3, o.z * 1e3);
    for (std::size_t c = 0; c < s.per_camera_offsets_mm.size(); ++c) {
      const Vec3d& p = s.per_camera_offsets_mm[c][k];
      fmt::print("{:>8}  {:<8} {:>9.3f} {:>9.3f} {:>9.3f}\n", "", s.camera_names[c], p.x * 1e3, p.y * 1e3, p.z * 1e3);
    }
  }
  fmt::print("(\"all\": joint estimate over the cameras, used for the correction; per camera: that view alone)\n\n");
}

nlohmann::json stage_offsets_json(const StageOffsets& s) {
  auto um = [](const Vec3d& v) { return nlohmann::json{v.x * 1e3, v.y * 1e3, v.z * 1e3}; };
  nlohmann::json planes = nlohmann::json::array();
  for (std::size_t k = 0; k < s.plane_z_mm.size(); ++k) {
    nlohmann::json per_camera = nlohmann::json::array();
    for (const auto& camera : s.per_camera_offsets_mm) per_camera.push_back(um(camera[k]));
    planes.push_back({{"z_nominal_mm", s.plane_z_mm[k]}, {"offset_um", um(s.offsets_mm[k])}, {"per_camera_um", per_camera}});
  }
  return {{"cycles", s.cycles},
          {"converged", s.converged},
          {"cameras", s.camera_names},
          {"gauge", "zero mean; no linear trend over z in x and z (traverse_correction.h)"},
          {"planes", planes}};
}

nlohmann::json report_json(const std::vector<ModelResult>& results) {
  nlohmann::json list = nlohmann::json::array();
  for (const ModelResult& r : results) {
    nlohmann::json planes = nlohmann::json::array();
    for (const PlaneResidual& p : r.planes)
      planes.push_back({{"z_mm", p.z_mm}, {"points", p.points}, {"forward_px", p.forward_px}, {"reverse_um", p.reverse_um}});
    if (!r.error.empty()) {
      list.push_back({{"camera", r.camera}, {"model", r.report.model}, {"error", r.error}});
      continue;
    }
    const auto& p = r.report;
    list.push_back({{"camera", r.camera},
                    {"model", p.model},
                    {"points", p.points},
                    {"planes", p.planes},
                    {"forward_px", p.forward_mean_px},
                    {"forward_rms_px", p.forward_rms_px},
                    {"forward_max_px", p.forward_max_px},
                    {"reverse_um", p.reverse_mean_um},
                    {"reverse_rms_um", p.reverse_rms_um},
                    {"reverse_max_um", p.reverse_max_um},
                    {"converged", p.converged},
                    {"retry", p.retry},
                    {"per_plane", planes}});
  }
  return list;
}

}  // namespace tomorig::app
