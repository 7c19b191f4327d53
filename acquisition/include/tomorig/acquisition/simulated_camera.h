#pragma once
// A camera rendered in software: for each trigger input it asks a renderer for frames A and B
// of that event (with the event's actual Δt) and delivers them like a real camera would.
// The renderer is supplied by the caller (the apps layer plugs the simulator in), so
// acquisition does not depend on simulators/.
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "tomorig/acquisition/camera.h"
#include "tomorig/acquisition/trigger_input.h"

namespace tomorig::acquisition {

struct RenderedPair {
  Image a;
  Image b;
};

// Renders camera `camera_id`'s frames A and B for one trigger event.
using FrameRenderer = std::function<RenderedPair(const std::string& camera_id, const TriggerInput& event)>;

// Faults a simulated camera can be told to have, so the rig's handling of a failing camera can
// be tested without hardware.
struct SimulatedCameraFaults {
  // The camera vanishes (cable pulled, power lost) after delivering this many trigger events:
  // later triggers produce nothing, and connected() turns false.
  std::optional<std::uint64_t> vanish_after_events;
};

class SimulatedCamera final : public Camera {
 public:
  // Throws bad_input for an empty id or renderer.
  SimulatedCamera(std::string id, FrameRenderer renderer, SimulatedCameraFaults faults = {});

  const std::string& id() const override { return id_; }
  // Accepts simulated cameras only; remembers the ROI so rendered sizes can be checked.
  void configure(const config::CameraConfig& config) override;
  void start(FrameSink sink) override;
  void stop() override;
  StreamStatistics statistics() const override;
  bool connected() const override;

  // Renders and delivers frames A (timestamp = event time) and B (event time + Δt) in the
  // calling thread. Ignored (counted as an underrun) when the camera is not started, and
  // ignored silently once an injected fault made it vanish (its frames are simply missing).
  // Throws runtime_error if the renderer returns an image whose size differs from the ROI.
  void trigger(const TriggerInput& event);

 private:
  std::string id_;
  FrameRenderer renderer_;
  config::CameraConfig config_;
  bool configured_ = false;
  mutable std::mutex mutex_;
  FrameSink sink_;
  bool running_ = false;
  StreamStatistics stats_;
  std::uint64_t next_frame_id_ = 0;
  SimulatedCameraFaults faults_;
  std::uint64_t events_delivered_ = 0;
  bool vanished_ = false;
};

}  // namespace tomorig::acquisition
