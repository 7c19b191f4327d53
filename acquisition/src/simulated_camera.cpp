#include "tomorig/acquisition/simulated_camera.h"

#include <fmt/format.h>

#include <utility>

#include "tomorig/core/error.h"

namespace tomorig::acquisition {

SimulatedCamera::SimulatedCamera(std::string id, FrameRenderer renderer, SimulatedCameraFaults faults)
    : id_(std::move(id)), renderer_(std::move(renderer)), faults_(faults) {
  if (id_.empty()) throw bad_input("simulated camera: the camera id is empty");
  if (!renderer_) throw bad_input(fmt::format("simulated camera {}: no frame renderer given", id_));
}

void SimulatedCamera::configure(const config::CameraConfig& config) {
  if (config.backend != config::CameraBackend::simulated)
    throw bad_input(fmt::format("camera {}: backend is '{}', but a simulated camera was asked to take it",
                                id_, config::to_string(config.backend)));
  std::lock_guard lock(mutex_);
  if (running_) throw runtime_error(fmt::format("camera {}: cannot configure while running; stop it first", id_));
  config_ = config;
  configured_ = true;
}

void SimulatedCamera::start(FrameSink sink) {
  if (!sink) throw bad_input(fmt::format("camera {}: start() needs a frame sink", id_));
  std::lock_guard lock(mutex_);
  if (!configured_) throw runtime_error(fmt::format("camera {}: start() before configure()", id_));
  sink_ = std::move(sink);
  running_ = true;
  stats_ = {};
  next_frame_id_ = 0;
}

void SimulatedCamera::stop() {
  std::lock_guard lock(mutex_);
  running_ = false;
  sink_ = nullptr;
}

StreamStatistics SimulatedCamera::statistics() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

bool SimulatedCamera::connected() const {
  std::lock_guard lock(mutex_);
  return !vanished_;
}

void SimulatedCamera::trigger(const TriggerInput& event) {
  // The whole trigger runs under the lock so stop() never races a delivery in progress:
  // after stop() returns, the sink is not called again.
  std::lock_guard lock(mutex_);
  if (!running_) {
    ++stats_.underruns;  // a trigger the camera was not ready for: its frames never exist
    return;
  }
  if (faults_.vanish_after_events && events_delivered_ >= *faults_.vanish_after_events) vanished_ = true;
  if (vanished_) return;  // a camera that is gone sends nothing; the assembler counts the loss
  ++events_delivered_;
  RenderedPair pair = renderer_(id_, event);
  const int want_w = config_.roi.width, want_h = config_.roi.height;
  for (const Image* image : {&pair.a, &pair.b}) {
    if (image->empty())
      throw runtime_error(fmt::format("camera {}: the renderer returned an empty frame for trigger {}", id_, event.index));
    if (want_w > 0 && want_h > 0 && (image->width() != want_w || image->height() != want_h))
      throw runtime_error(fmt::format("camera {}: rendered frame is {} x {} but the ROI is {} x {}", id_,
                                      image->width(), image->height(), want_w, want_h));
  }
  const std::int64_t times[2] = {event.timestamp_ns, event.timestamp_ns + event.dt_ns};
  Image* images[2] = {&pair.a, &pair.b};
  for (int k = 0; k < 2; ++k) {
    CameraFrame frame;
    frame.trigger_index = event.index;
    frame.exposure = k == 0 ? Exposure::A : Exposure::B;
    frame.frame_id = next_frame_id_++;
    frame.timestamp_ns = times[k];
    frame.trigger_timestamp_ns = event.timestamp_ns;
    frame.dt_ns = event.dt_ns;
    frame.image = std::move(*images[k]);
    ++stats_.completed;
    ++stats_.delivered;
    sink_(std::move(frame));
  }
}

}  // namespace tomorig::acquisition
