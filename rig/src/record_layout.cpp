#include "tomorig/rig/record_layout.h"

#include <fmt/core.h>

namespace tomorig::rig {
namespace {

std::optional<PixelFormat> format_of(SampleType type) {
  switch (type) {
    case SampleType::u8: return PixelFormat::Mono8;
    case SampleType::u16: return PixelFormat::Mono16;
    default: return std::nullopt;  // float frames are not camera data
  }
}

bool frame_matches(const Frame& frame, const storage::SessionCamera& cam, char exposure, std::string& why) {
  if (!frame.present()) return true;  // recorded as missing
  const Image& im = frame.image;
  if (im.width() != cam.width || im.height() != cam.height || im.type() != sample_type_of(cam.pixel_format)) {
    why = fmt::format("camera '{}' frame {} is {}x{} {}, but the session has {}x{} {}", cam.id, exposure, im.width(),
                      im.height(), to_string(im.type()), cam.width, cam.height, to_string(cam.pixel_format));
    return false;
  }
  return true;
}

}  // namespace

std::optional<std::vector<storage::SessionCamera>> cameras_from_set(const FrameSet& set, std::string& why) {
  if (set.cameras.empty()) {
    why = "it holds no cameras";
    return std::nullopt;
  }
  std::vector<storage::SessionCamera> cameras;
  for (const CameraFrames& c : set.cameras) {
    const Frame& known = c.a.present() ? c.a : c.b;
    if (!known.present()) {
      why = fmt::format("camera '{}' has neither frame, so its size is unknown", c.camera_id);
      return std::nullopt;
    }
    const auto format = format_of(known.image.type());
    if (!format) {
      why = fmt::format("camera '{}' sends {} samples; only 8- and 16-bit camera frames can be recorded", c.camera_id,
                        to_string(known.image.type()));
      return std::nullopt;
    }
    storage::SessionCamera cam;
    cam.id = c.camera_id;
    cam.width = known.image.width();
    cam.height = known.image.height();
    cam.pixel_format = *format;
    if (!frame_matches(c.a, cam, 'A', why) || !frame_matches(c.b, cam, 'B', why)) return std::nullopt;
    cameras.push_back(std::move(cam));
  }
  return cameras;
}

std::optional<std::vector<storage::SessionCamera>> complete_announced_cameras(
    const std::vector<storage::SessionCamera>& announced, const FrameSet& set, std::string& why) {
  bool sizes_known = true;
  for (const auto& cam : announced) sizes_known &= cam.width > 0 && cam.height > 0;
  if (sizes_known) return announced;
  const auto learned = cameras_from_set(set, why);
  if (!learned) return std::nullopt;
  if (learned->size() != announced.size()) {
    why = fmt::format("it has {} cameras, the session start announced {}", learned->size(), announced.size());
    return std::nullopt;
  }
  std::vector<storage::SessionCamera> cameras = announced;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const storage::SessionCamera& got = (*learned)[i];
    if (got.id != cameras[i].id) {
      why = fmt::format("camera {} is '{}', the session start announced '{}'", i, got.id, cameras[i].id);
      return std::nullopt;
    }
    if (sample_type_of(got.pixel_format) != sample_type_of(cameras[i].pixel_format)) {
      why = fmt::format("camera '{}' sends {} frames, the session start announced {}", got.id,
                        to_string(got.pixel_format), to_string(cameras[i].pixel_format));
      return std::nullopt;
    }
    if (cameras[i].width == 0 || cameras[i].height == 0) {
      cameras[i].width = got.width;
      cameras[i].height = got.height;
    }
  }
  return cameras;
}

bool set_matches_cameras(const FrameSet& set, const std::vector<storage::SessionCamera>& cameras, std::string& why) {
  if (set.cameras.size() != cameras.size()) {
    why = fmt::format("it has {} cameras, the session {}", set.cameras.size(), cameras.size());
    return false;
  }
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    if (set.cameras[i].camera_id != cameras[i].id) {
      why = fmt::format("camera {} is '{}', the session's is '{}'", i, set.cameras[i].camera_id, cameras[i].id);
      return false;
    }
    if (!frame_matches(set.cameras[i].a, cameras[i], 'A', why) || !frame_matches(set.cameras[i].b, cameras[i], 'B', why))
      return false;
  }
  return true;
}

std::uint64_t pixel_bytes(const FrameSet& set) {
  std::uint64_t bytes = 0;
  for (const CameraFrames& c : set.cameras)
    for (const Frame* f : {&c.a, &c.b})
      if (f->present()) bytes += f->image.size_bytes();
  return bytes;
}

}  // namespace tomorig::rig
