#pragma once
// A camera of the rig, whatever its backend (Aravis GenICam or simulated): configured from the
// rig configuration, started with a sink that receives every good frame, stopped. Frames are
// Image views; a view over a camera buffer holds a lease that gives the buffer back to the
// camera's pool when the last Image referring to it dies (no copy on receipt).
#include <cstdint>
#include <functional>
#include <string>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/frame_set.h"
#include "tomorig/core/image.h"

namespace tomorig::acquisition {

// One frame as a camera delivers it, already placed in its double-frame set.
struct CameraFrame {
  std::uint64_t trigger_index = 0;      // the set (trigger event) this frame belongs to
  Exposure exposure = Exposure::A;      // frame A or frame B of the set
  std::uint64_t frame_id = 0;           // frames since start (0: the first), unwrapped to 64 bits
  std::int64_t timestamp_ns = 0;        // camera clock
  std::int64_t trigger_timestamp_ns = 0;  // trigger clock; 0: unknown to the camera
  std::int64_t dt_ns = 0;               // pulse separation of the event; 0: unknown
  Image image;
};

// Called from the camera's delivery thread (Aravis) or from the triggering thread (simulated).
// It must be thread-safe and quick: FrameSetAssembler::add_frame is the usual sink.
using FrameSink = std::function<void(CameraFrame&&)>;

// What a camera's stream has seen since start(). Aravis fills every field from its stream
// statistics; a simulated camera loses nothing, so only the frame counters move.
struct StreamStatistics {
  std::uint64_t completed = 0;        // buffers completed by the stream
  std::uint64_t failures = 0;         // buffers that arrived incomplete or corrupt (never delivered)
  std::uint64_t underruns = 0;        // frames dropped because no buffer was free
  std::uint64_t missing_packets = 0;  // GigE Vision packets never received
  std::uint64_t resends = 0;          // GigE Vision packets received after a resend request
  std::uint64_t delivered = 0;        // frames handed to the sink
  std::uint64_t frame_id_gaps = 0;    // frames the frame-id sequence says never arrived
};

class Camera {
 public:
  virtual ~Camera() = default;
  Camera() = default;
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  // The rig's camera id ("cam0"), used in every message.
  virtual const std::string& id() const = 0;
  // Applies the configuration. Throws tomorig::Error: bad_input for a setting the camera
  // cannot take (the message names the camera and the feature), runtime for a device fault.
  virtual void configure(const config::CameraConfig& config) = 0;
  // Starts delivering frames to `sink`. Throws tomorig::Error if not configured.
  virtual void start(FrameSink sink) = 0;
  // Stops delivery; after it returns the sink is not called again. Idempotent.
  virtual void stop() = 0;
  virtual StreamStatistics statistics() const = 0;
  // False once the camera is known to be gone (unplugged, powered off, stopped answering).
  // Its frames then go missing in the assembler, where they are counted; the rig decides
  // whether to go on without it. Backends that cannot tell report true.
  virtual bool connected() const { return true; }
  // Why connected() turned false ("no frame 500 ms after its trigger", ...); empty while connected.
  virtual std::string connection_problem() const { return {}; }
};

}  // namespace tomorig::acquisition
