#include "tomorig/acquisition/aravis_camera.h"

#include <arv.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "aravis_buffer_pool.h"
#include "genicam_features.h"
#include "glib_handles.h"
#include "tomorig/acquisition/frame_id.h"
#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

using detail::GErrorSlot;
using detail::GObjectPtr;

constexpr guint64 kPopTimeoutUs = 100'000;  // how often the delivery thread checks for stop()

// Sample type of the pixel formats tomorig stores; nullopt for packed or colour formats.
std::optional<SampleType> sample_type_of_arv(ArvPixelFormat format) {
  switch (format) {
    case ARV_PIXEL_FORMAT_MONO_8: return SampleType::u8;
    case ARV_PIXEL_FORMAT_MONO_10:
    case ARV_PIXEL_FORMAT_MONO_12:
    case ARV_PIXEL_FORMAT_MONO_14:
    case ARV_PIXEL_FORMAT_MONO_16: return SampleType::u16;
    default: return std::nullopt;
  }
}

}  // namespace

std::vector<std::string> list_aravis_devices() {
  arv_update_device_list();
  std::vector<std::string> devices;
  const unsigned n = arv_get_n_devices();
  for (unsigned i = 0; i < n; ++i) {
    const char* id = arv_get_device_id(i);
    const char* address = arv_get_device_address(i);
    devices.push_back(fmt::format("{} ({})", id != nullptr ? id : "?", address != nullptr ? address : "?"));
  }
  return devices;
}

struct AravisCamera::Impl {
  std::string id;
  AravisCameraOptions options;
  config::CameraConfig config;
  GObjectPtr<ArvCamera> camera;
  std::shared_ptr<detail::AravisBufferPool> pool;  // kept after stop() so statistics stay readable
  mutable std::mutex pool_mutex;  // guards the `pool` pointer for statistics() (sinks may call it)
  std::size_t payload = 0;

  std::mutex mutex;  // guards start/stop/configure against each other
  std::thread delivery;
  std::atomic<bool> running{false};
  FrameSink sink;
  std::atomic<std::uint64_t> delivered{0};
  std::atomic<std::uint64_t> frame_id_gaps{0};
  std::atomic<std::uint64_t> rejected{0};  // complete buffers refused (size, pixel format)

  void open(const std::string& device_id);
  void apply(const config::CameraConfig& cfg);
  void deliver_loop();
  void deliver(ArvBuffer* buffer, FrameIdUnwrapper& unwrapper);
};

void AravisCamera::Impl::open(const std::string& device_id) {
  GErrorSlot error;
  ArvCamera* opened = arv_camera_new(device_id.c_str(), error.out());
  if (opened == nullptr) {
    const auto found = list_aravis_devices();
    throw runtime_error(fmt::format(
        "camera {}: Aravis device '{}' not found ({}). Devices found: {}. Check that the camera is powered and "
        "connected, and that device_id is an id or address from this list",
        id, device_id, error ? error.message() : "no such device",
        found.empty() ? std::string("none") : fmt::format("{}", fmt::join(found, ", "))));
  }
  camera.reset(opened);
}

void AravisCamera::Impl::apply(const config::CameraConfig& cfg) {
  ArvDevice* device = arv_camera_get_device(camera.get());
  detail::set_feature(device, id, "PixelFormat", std::string(to_string(cfg.pixel_format)));
  if (cfg.roi.width > 0 && cfg.roi.height > 0) {
    // Offsets first to 0 so any width fits, then the size, then the real offsets.
    if (detail::has_feature(device, "OffsetX")) detail::set_feature(device, id, "OffsetX", "0");
    if (detail::has_feature(device, "OffsetY")) detail::set_feature(device, id, "OffsetY", "0");
    detail::set_feature(device, id, "Width", std::to_string(cfg.roi.width));
    detail::set_feature(device, id, "Height", std::to_string(cfg.roi.height));
    if (cfg.roi.offset_x != 0 || detail::has_feature(device, "OffsetX"))
      detail::set_feature(device, id, "OffsetX", std::to_string(cfg.roi.offset_x));
    if (cfg.roi.offset_y != 0 || detail::has_feature(device, "OffsetY"))
      detail::set_feature(device, id, "OffsetY", std::to_string(cfg.roi.offset_y));
  }
  if (!options.acquisition_mode.empty()) detail::set_feature(device, id, "AcquisitionMode", options.acquisition_mode);
  if (!options.trigger_mode.empty()) {
    if (detail::has_feature(device, "TriggerSelector")) detail::set_feature(device, id, "TriggerSelector", "FrameStart");
    detail::set_feature(device, id, "TriggerMode", options.trigger_mode);
    if (options.trigger_mode == "On" && !options.trigger_source.empty())
      detail::set_feature(device, id, "TriggerSource", options.trigger_source);
  }
  if (options.exposure_time_us) {
    const char* name = detail::has_feature(device, "ExposureTime") ? "ExposureTime" : "ExposureTimeAbs";
    detail::set_feature(device, id, name, fmt::format("{}", *options.exposure_time_us));
  }
  if (options.packet_size > 0) {
    if (!arv_camera_is_gv_device(camera.get()))
      throw bad_input(fmt::format("camera {}: a packet size was given but the camera is not a GigE Vision camera "
                                  "(GevSCPSPacketSize applies to GigE only)", id));
    detail::set_feature(device, id, "GevSCPSPacketSize", std::to_string(options.packet_size));
  }
  for (const auto& [name, value] : cfg.features) detail::set_feature(device, id, name, value);

  GErrorSlot error;
  payload = arv_camera_get_payload(camera.get(), error.out());
  if (error || payload == 0)
    throw runtime_error(fmt::format("camera {}: cannot read the payload size: {}", id, error.message()));
}

void AravisCamera::Impl::deliver(ArvBuffer* buffer, FrameIdUnwrapper& unwrapper) {
  const guint64 raw_id = arv_buffer_get_frame_id(buffer);
  if (raw_id == 0 && options.frame_id_zero_reserved) {  // failed before any packet said which frame
    pool->give_back(buffer);
    return;
  }
  const auto sequence = unwrapper.unwrap(raw_id);
  frame_id_gaps = unwrapper.gaps();
  // Incomplete or corrupt buffers still move the frame-id sequence (so later frames keep
  // their A/B role) but are never delivered: Aravis counts them as failures.
  if (!sequence) {  // stale or duplicate id: not a frame of this acquisition's sequence
    pool->give_back(buffer);
    return;
  }
  auto reject = [&] {
    pool->give_back(buffer);
    if (options.on_failed_frame) options.on_failed_frame(*sequence);
  };
  if (arv_buffer_get_status(buffer) != ARV_BUFFER_STATUS_SUCCESS) {
    reject();
    return;
  }
  const auto type = sample_type_of_arv(arv_buffer_get_image_pixel_format(buffer));
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  std::size_t size = 0;
  const void* data = arv_buffer_get_image_data(buffer, &size);
  if (!type || width <= 0 || height <= 0 || data == nullptr ||
      size < static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * bytes_per_sample(*type)) {
    ++rejected;  // Aravis saw a good buffer; tomorig cannot use it, so it is a failure too
    reject();
    return;
  }
  CameraFrame frame;
  frame.frame_id = *sequence;
  frame.trigger_index = *sequence / 2;
  frame.exposure = *sequence % 2 == 0 ? Exposure::A : Exposure::B;
  frame.timestamp_ns = static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer));
  frame.image = Image::view(const_cast<void*>(data), width, height, *type, 0, pool->lease(buffer));
  ++delivered;
  sink(std::move(frame));
}

void AravisCamera::Impl::deliver_loop() {
  FrameIdUnwrapper unwrapper(options.frame_id_bits, options.frame_id_zero_reserved);
  if (options.first_frame_id) unwrapper.expect_first(*options.first_frame_id);
  while (running) {
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(pool->stream(), kPopTimeoutUs);
    if (buffer != nullptr) deliver(buffer, unwrapper);
  }
}

AravisCamera::AravisCamera(std::string id, AravisCameraOptions options) : impl_(std::make_unique<Impl>()) {
  if (id.empty()) throw bad_input("aravis camera: the camera id is empty");
  if (options.buffer_count < 2)
    throw bad_input(fmt::format("camera {}: buffer_count = {}: must be >= 2", id, options.buffer_count));
  if (options.packet_size < 0 || options.socket_buffer_bytes < 0 || options.frame_retention_us < 0)
    throw bad_input(fmt::format("camera {}: packet size, socket buffer and frame retention must be >= 0", id));
  impl_->id = std::move(id);
  impl_->options = std::move(options);
  FrameIdUnwrapper check(impl_->options.frame_id_bits, impl_->options.frame_id_zero_reserved);  // validates
}

AravisCamera::~AravisCamera() { stop(); }

const std::string& AravisCamera::id() const { return impl_->id; }

int AravisCamera::triggers_per_set() const { return impl_->options.mode == DoubleFrameMode::double_frame ? 1 : 2; }

void AravisCamera::configure(const config::CameraConfig& config) {
  std::lock_guard lock(impl_->mutex);
  if (impl_->running) throw runtime_error(fmt::format("camera {}: cannot configure while running; stop it first", impl_->id));
  if (config.backend != config::CameraBackend::aravis)
    throw bad_input(fmt::format("camera {}: backend is '{}', but an Aravis camera was asked to take it", impl_->id,
                                config::to_string(config.backend)));
  if (config.device_id.empty())
    throw bad_input(fmt::format("camera {}: device_id is empty: give the Aravis device id or IP address", impl_->id));
  if (!impl_->camera || config.device_id != impl_->config.device_id) {
    impl_->camera.reset();
    impl_->open(config.device_id);
  }
  impl_->config = config;
  impl_->apply(config);
}

void AravisCamera::start(FrameSink sink) {
  if (!sink) throw bad_input(fmt::format("camera {}: start() needs a frame sink", impl_->id));
  std::lock_guard lock(impl_->mutex);
  if (impl_->running) return;
  if (!impl_->camera) throw runtime_error(fmt::format("camera {}: start() before configure()", impl_->id));
  GErrorSlot error;
  ArvStream* stream = arv_camera_create_stream(impl_->camera.get(), nullptr, nullptr, error.out());
  if (stream == nullptr)
    throw runtime_error(fmt::format("camera {}: cannot open the stream: {}", impl_->id, error.message()));
  GObjectPtr<ArvStream> stream_ref(stream);
  if (ARV_IS_GV_STREAM(stream)) {
    if (impl_->options.socket_buffer_bytes > 0)
      g_object_set(stream, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size",
                   impl_->options.socket_buffer_bytes, nullptr);
    if (impl_->options.frame_retention_us > 0)
      g_object_set(stream, "frame-retention", static_cast<guint>(impl_->options.frame_retention_us), nullptr);
    // Ask for lost packets again rather than accept a frame with holes.
    g_object_set(stream, "packet-resend", ARV_GV_STREAM_PACKET_RESEND_ALWAYS, nullptr);
  }
  {
    std::lock_guard pool_lock(impl_->pool_mutex);
    impl_->pool = detail::AravisBufferPool::create(stream, impl_->payload, impl_->options.buffer_count);
  }
  impl_->sink = std::move(sink);
  impl_->delivered = 0;
  impl_->frame_id_gaps = 0;
  impl_->rejected = 0;
  impl_->running = true;
  impl_->delivery = std::thread([impl = impl_.get()] { impl->deliver_loop(); });
  arv_camera_start_acquisition(impl_->camera.get(), error.out());
  if (error) {
    impl_->running = false;
    impl_->delivery.join();
    throw runtime_error(fmt::format("camera {}: AcquisitionStart failed: {}", impl_->id, error.message()));
  }
}

void AravisCamera::stop() {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->running) return;
  impl_->running = false;
  if (impl_->delivery.joinable()) impl_->delivery.join();
  GErrorSlot error;
  if (impl_->camera) arv_camera_stop_acquisition(impl_->camera.get(), error.out());  // a vanished camera: nothing to stop
  impl_->sink = nullptr;
}

void AravisCamera::software_trigger() {
  if (!impl_->camera) throw runtime_error(fmt::format("camera {}: software trigger before configure()", impl_->id));
  GErrorSlot error;
  arv_camera_software_trigger(impl_->camera.get(), error.out());
  if (error) throw runtime_error(fmt::format("camera {}: TriggerSoftware failed: {}", impl_->id, error.message()));
}

StreamStatistics AravisCamera::statistics() const {
  StreamStatistics s;
  s.delivered = impl_->delivered;
  s.frame_id_gaps = impl_->frame_id_gaps;
  std::shared_ptr<detail::AravisBufferPool> pool;
  {
    std::lock_guard pool_lock(impl_->pool_mutex);
    pool = impl_->pool;
  }
  if (!pool) return s;
  guint64 completed = 0, failures = 0, underruns = 0;
  arv_stream_get_statistics(pool->stream(), &completed, &failures, &underruns);
  s.completed = completed;
  s.failures = failures + impl_->rejected;
  s.underruns = underruns;
  if (ARV_IS_GV_STREAM(pool->stream())) {
    guint64 resent = 0, missing = 0;
    arv_gv_stream_get_statistics(ARV_GV_STREAM(pool->stream()), &resent, &missing);
    s.resends = resent;
    s.missing_packets = missing;
  }
  return s;
}

}  // namespace tomorig::acquisition
