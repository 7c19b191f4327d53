#pragma once
// How an AravisCamera reaches its device: opening it (by Aravis device id, or through a GenTL
// producer), the payload size and the frame stream. Everything else (features, frame modes,
// triggers, matching, loss counting) is the camera's own and shared by every backend.
#include <arv.h>

#include <cstddef>
#include <memory>
#include <string>

#include "frame_stream.h"
#include "tomorig/acquisition/aravis_camera.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::acquisition::detail {

class CameraBackend {
 public:
  virtual ~CameraBackend() = default;
  // The rig-file backend this one serves ("aravis", "gentl").
  virtual config::CameraBackend kind() const = 0;
  // Opens the device `config` names; returns a new ArvCamera reference. Throws tomorig::Error
  // naming the camera (runtime: absent device; bad_input: a producer that cannot be used).
  virtual ArvCamera* open(const std::string& camera_id, const config::CameraConfig& config) = 0;
  // Bytes of one frame, read after the features were applied.
  virtual std::size_t payload(ArvCamera* camera, const std::string& camera_id) = 0;
  // A started stream with `options.buffer_count` buffers of `payload` bytes queued.
  virtual std::shared_ptr<FrameStream> open_stream(ArvCamera* camera, std::size_t payload,
                                                   const AravisCameraOptions& options, const std::string& camera_id) = 0;
};

std::unique_ptr<CameraBackend> make_aravis_backend();

}  // namespace tomorig::acquisition::detail
