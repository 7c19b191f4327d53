// The GenTL backend: opening a camera through a GenTL producer, its payload and its stream.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "../camera_backend.h"
#include "../glib_handles.h"
#include "gentl_arv_device.h"
#include "gentl_stream.h"
#include "tomorig/acquisition/gentl_camera.h"
#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace gentl_detail {
namespace {

class GenTLBackend final : public detail::CameraBackend {
 public:
  config::CameraBackend kind() const override { return config::CameraBackend::gentl; }

  ArvCamera* open(const std::string& id, const config::CameraConfig& config) override {
    stream_.reset();
    if (config.device_id.empty())
      throw bad_input(fmt::format("camera {}: device_id is empty: give the GenTL device id, serial number or "
                                  "user-defined name",
                                  id));
    const std::string what = fmt::format("camera {}", id);
    std::vector<std::filesystem::path> producers;
    if (!config.producer.empty())
      producers.push_back(config.producer);
    else
      producers = Producer::from_environment();
    std::vector<std::string> seen;
    std::vector<std::string> unusable;  // GENICAM_GENTL64_PATH only: producers that failed to load
    for (const auto& path : producers) {
      std::shared_ptr<Producer> producer;
      if (!config.producer.empty()) {
        try {
          producer = Producer::load(path);  // the rig's own choice: its errors are the answer
        } catch (const Error& e) {
          throw Error(e.kind(), fmt::format("camera {}: {}", id, e.what()));
        }
      } else {
        // The variable often lists every vendor's producer; one that cannot load (no grabber,
        // no licence) must not hide the camera on another.
        try {
          producer = Producer::load(path);
        } catch (const Error& e) {
          unusable.push_back(e.what());
          continue;
        }
      }
      std::shared_ptr<Device> device = producer->open_device(config.device_id);
      if (!device) {
        for (auto& listed : producer->list_devices()) seen.push_back(fmt::format("{} [{}]", listed, path.filename().string()));
        continue;
      }
      ArvDevice* arv_device = new_arv_device(device, what);
      detail::GErrorSlot error;
      ArvCamera* camera = arv_camera_new_with_device(arv_device, error.out());
      g_object_unref(arv_device);  // the camera holds its own reference
      if (camera == nullptr)
        throw runtime_error(fmt::format("{}: Aravis cannot make a camera of GenTL device '{}': {}", what,
                                        device->id(), error.message()));
      stream_ = std::make_shared<DataStream>(device, what);
      return camera;
    }
    throw runtime_error(fmt::format("camera {}: GenTL device '{}' not found. Devices found: {}. Check that the camera "
                                    "is powered and connected to the grabber, and that device_id is an id, serial "
                                    "number or user-defined name from this list{}",
                                    id, config.device_id,
                                    seen.empty() ? std::string("none") : fmt::format("{}", fmt::join(seen, "; ")),
                                    unusable.empty() ? std::string()
                                                     : fmt::format(". Producers skipped: {}", fmt::join(unusable, "; "))));
  }

  // The stream's own size when it defines it (a grabber that adds chunk data or line padding),
  // else the camera's PayloadSize, else whatever the stream says.
  std::size_t payload(ArvCamera* camera, const std::string& id) override {
    if (stream_->defines_payload() && stream_->payload() > 0) return stream_->payload();
    if (arv_device_is_feature_implemented(arv_camera_get_device(camera), "PayloadSize", nullptr)) {
      detail::GErrorSlot error;
      const std::size_t bytes = arv_camera_get_payload(camera, error.out());
      if (!error && bytes > 0) return bytes;
    }
    if (const std::size_t bytes = stream_->payload(); bytes > 0) return bytes;
    throw runtime_error(fmt::format("camera {}: neither the camera (PayloadSize) nor the GenTL stream "
                                    "(STREAM_INFO_PAYLOAD_SIZE) gives the payload size",
                                    id));
  }

  std::shared_ptr<detail::FrameStream> open_stream(ArvCamera*, std::size_t payload, const AravisCameraOptions& options,
                                                   const std::string& id) override {
    return GenTLFrameStream::create(stream_, payload, options.buffer_count, fmt::format("camera {}", id));
  }

 private:
  std::shared_ptr<DataStream> stream_;
};

}  // namespace
}  // namespace gentl_detail

std::unique_ptr<AravisCamera> make_gentl_camera(std::string id, AravisCameraOptions options) {
  options.frame_id_bits = 63;  // GenTL frame ids are 64-bit counters that do not wrap in practice
  options.frame_id_zero_reserved = false;
  options.packet_size = 0;
  return std::make_unique<AravisCamera>(std::move(id), std::move(options),
                                        std::make_unique<gentl_detail::GenTLBackend>());
}

}  // namespace tomorig::acquisition
