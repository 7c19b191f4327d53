// The Aravis backend: GigE Vision and USB3 Vision cameras Aravis finds by itself.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "aravis_buffer_pool.h"
#include "camera_backend.h"
#include "glib_handles.h"
#include "tomorig/core/error.h"

namespace tomorig::acquisition::detail {
namespace {

class AravisBackend final : public CameraBackend {
 public:
  config::CameraBackend kind() const override { return config::CameraBackend::aravis; }

  ArvCamera* open(const std::string& id, const config::CameraConfig& config) override {
    if (config.device_id.empty())
      throw bad_input(fmt::format("camera {}: device_id is empty: give the Aravis device id or IP address", id));
    GErrorSlot error;
    ArvCamera* opened = arv_camera_new(config.device_id.c_str(), error.out());
    if (opened == nullptr) {
      const auto found = list_aravis_devices();
      throw runtime_error(fmt::format(
          "camera {}: Aravis device '{}' not found ({}). Devices found: {}. Check that the camera is powered and "
          "connected, and that device_id is an id or address from this list",
          id, config.device_id, error ? error.message() : "no such device",
          found.empty() ? std::string("none") : fmt::format("{}", fmt::join(found, ", "))));
    }
    return opened;
  }

  std::size_t payload(ArvCamera* camera, const std::string& id) override {
    GErrorSlot error;
    const std::size_t bytes = arv_camera_get_payload(camera, error.out());
    if (error || bytes == 0)
      throw runtime_error(fmt::format("camera {}: cannot read the payload size: {}", id, error.message()));
    return bytes;
  }

  std::shared_ptr<FrameStream> open_stream(ArvCamera* camera, std::size_t payload, const AravisCameraOptions& options,
                                           const std::string& id) override {
    GErrorSlot error;
    ArvStream* stream = arv_camera_create_stream(camera, nullptr, nullptr, error.out());
    if (stream == nullptr)
      throw runtime_error(fmt::format("camera {}: cannot open the stream: {}", id, error.message()));
    GObjectPtr<ArvStream> stream_ref(stream);
    if (ARV_IS_GV_STREAM(stream)) {
      if (options.socket_buffer_bytes > 0)
        g_object_set(stream, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size",
                     options.socket_buffer_bytes, nullptr);
      if (options.frame_retention_us > 0)
        g_object_set(stream, "frame-retention", static_cast<guint>(options.frame_retention_us), nullptr);
      // Ask for lost packets again rather than accept a frame with holes.
      g_object_set(stream, "packet-resend", ARV_GV_STREAM_PACKET_RESEND_ALWAYS, nullptr);
    }
    return AravisBufferPool::create(stream, payload, options.buffer_count);
  }
};

}  // namespace

std::unique_ptr<CameraBackend> make_aravis_backend() { return std::make_unique<AravisBackend>(); }

}  // namespace tomorig::acquisition::detail
