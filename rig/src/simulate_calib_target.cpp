// The calib-thesis case as a session file: one set per plane, truth alongside.
#include "tomorig/rig/simulate_calib_target.h"
#include "tomorig/rig/simulate_session.h"

#include <chrono>
#include <ctime>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/core/version.h"

namespace tomorig::rig {

std::string calib_target_truth_json(const sim::CalibTargetCase& c) {
  nlohmann::json planes = nlohmann::json::array();
  for (std::size_t k = 0; k < c.planes.size(); ++k) {
    const auto& p = c.planes[k];
    planes.push_back({{"set", k},
                      {"z_nominal_mm", p.z_nominal_mm},
                      {"offset_um", {p.offset_mm.x * 1e3, p.offset_mm.y * 1e3, p.offset_mm.z * 1e3}}});
  }
  nlohmann::json distortion = nlohmann::json::array();
  for (const auto& cam : c.cameras)
    distortion.push_back({{"id", cam.id}, {"yaw_deg", cam.yaw_deg}, {"k1", cam.k1}, {"pixel_pitch_um", cam.pixel_pitch_um}});
  const nlohmann::json j = {
      {"target", "chessboard"},
      {"inner_corners", {c.board.inner_corners_x, c.board.inner_corners_y}},
      {"square_mm", c.board.square_mm},
      {"world_frame", "board: corner (i, j) at (i, j) * square_mm + offset, z = z_nominal + offset.z; x right, y "
                      "down as seen, z away from the cameras"},
      {"planes", planes},
      {"distortion", "u_d = c + (u - c) (1 + k1 r^2), r = |u - c| / half image diagonal"},
      {"cameras", distortion},
      {"reduced", c.options.reduced},
      {"noise", c.options.noise},
      {"blur_sigma_px", c.options.blur_sigma_px}};
  return j.dump();
}

std::string write_calib_target_session(const sim::CalibTargetOptions& options, const std::filesystem::path& out,
                                       storage::Compression compression, bool overwrite) {
  const auto start = std::chrono::steady_clock::now();
  const sim::CalibTargetCase c = sim::make_calib_thesis_case(options);
  storage::SessionInfo info;
  for (const auto& cam : c.cameras)
    info.cameras.push_back({cam.id, cam.width, cam.height, PixelFormat::Mono16, cam.pixel_pitch_um});
  info.rig_config_toml = fmt::format(
      "# Written by `tomorig simulate --case calib-thesis`: a chessboard ({} x {} inner corners, {} mm) on a\n"
      "# traverse; set k shows plane k (z_nominal_mm in /truth, flow_parameters). No rig config applies.\n",
      c.board.inner_corners_x, c.board.inner_corners_y, c.board.square_mm);
  info.software_version = std::string(software_version());
  info.compression = compression;
  storage::SessionWriterOptions wo;
  wo.compression = compression;
  wo.overwrite = overwrite;
  storage::SessionWriter writer(out, info, wo);

  storage::SessionTruth truth;
  truth.case_name = c.name;
  truth.flow_name = "traverse";
  truth.flow_parameters = calib_target_truth_json(c);
  truth.seed = options.seed;
  for (const auto& cam : c.cameras) truth.cameras.push_back(truth_camera_of(cam.id, cam.pinhole, cam.width, cam.height));
  writer.write_truth(truth);
  for (std::size_t k = 0; k < c.planes.size(); ++k) {
    FrameSet set;
    set.set_index = k;
    for (std::size_t cam = 0; cam < c.cameras.size(); ++cam) {
      CameraFrames frames;
      frames.camera_id = c.cameras[cam].id;
      frames.a.image = sim::render_target_view(c, cam, k);
      set.cameras.push_back(std::move(frames));
    }
    writer.append(set);
    writer.write_truth_set(k, {});
  }
  writer.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fmt::format("wrote {}: calib-thesis{}, {} planes x {} cameras, {} x {} px, seed {}, {:.1f} s", out.string(),
                     options.reduced ? " (reduced)" : "", c.planes.size(), c.cameras.size(), c.cameras[0].width,
                     c.cameras[0].height, options.seed, seconds);
}

}  // namespace tomorig::rig
