// Residual tables of `tomorig calibrate`; see calibrate_report.h.
#include "calibrate_report.h"

#include <map>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/processing/calibration/fit_camera_model.h"

namespace tomorig::app {

std::vector<PlaneResidual> plane_residuals(const calibration::CameraModel& model,
                                           std::span<const calibration::PointCorrespondence> points) {
  std::map<double, std::vector<calibration::PointCorrespondence>> by_z;
  for (const auto& p : points) by_z[p.world.z].push_back(p);
  std::vector<PlaneResidual> planes;
  for (const auto& [z, plane_points] : by_z) {
    calibration::FitReport report;
    calibration::measure_residuals(model, plane_points, report);
    planes.push_back({z, static_cast<int>(plane_points.size()), report.forward_mean_px, report.reverse_mean_um});
  }
  return planes;
}

void print_report(const std::vector<ModelResult>& results, const std::string& stored, const std::string& out) {
  fmt::print("{:>6}  {:<10} {:>7} {:>7} {:>12} {:>12} {:>10}\n", "camera", "model", "points", "planes", "forward px",
             "reverse um", "converged");
  for (const ModelResult& r : results)
    fmt::print("{:>6}  {:<10} {:>7} {:>7} {:>12.4g} {:>12.4g} {:>10}\n", r.camera, r.report.model, r.report.points,
               r.report.planes, r.report.forward_mean_px, r.report.reverse_mean_um, r.report.converged ? "yes" : "no");
  fmt::print("\nper plane:\n{:>6}  {:<10} {:>10} {:>7} {:>12} {:>12}\n", "camera", "model", "z mm", "points", "forward px",
             "reverse um");
  for (const ModelResult& r : results)
    for (const PlaneResidual& p : r.planes)
      fmt::print("{:>6}  {:<10} {:>10.4g} {:>7} {:>12.4g} {:>12.4g}\n", r.camera, r.report.model, p.z_mm, p.points,
                 p.forward_px, p.reverse_um);
  fmt::print("wrote {} (model {} for every camera)\n", out, stored);
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
    list.push_back({{"camera", r.camera},
                    {"model", r.report.model},
                    {"points", r.report.points},
                    {"planes", r.report.planes},
                    {"forward_px", r.report.forward_mean_px},
                    {"reverse_um", r.report.reverse_mean_um},
                    {"converged", r.report.converged},
                    {"per_plane", planes}});
  }
  return list;
}

}  // namespace tomorig::app
