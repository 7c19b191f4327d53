#pragma once
// A GenICam camera through Aravis 0.8's GenApi engine: GigE Vision or USB3 Vision cameras
// Aravis finds itself (backend "aravis"), or a frame grabber's cameras through a GenTL
// producer (backend "gentl", make_gentl_camera in gentl_camera.h). Both share everything but
// how the device is opened and where the frames come from. Aravis and GLib stay in src/;
// this header only names the options.
//
//   AravisCameraOptions opt;  opt.trigger_source = "Software";
//   AravisCamera cam("cam0", opt);
//   cam.configure(rig.cameras[0]);     // opens config.device_id, applies the features
//   cam.start([&](CameraFrame&& f) { assembler.add_frame(0, std::move(f)); });
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/acquisition/camera.h"

namespace tomorig::acquisition {
namespace detail {
class CameraBackend;
}

struct AravisCameraOptions {
  // GenICam settings applied by configure(), before the [cameras.features] of the
  // configuration (which may override any of them). Empty strings leave the camera's value.
  std::string acquisition_mode = "Continuous";
  // How the camera makes frames A and B (frames alternate A, B, A, B..., so frame k of the
  // stream belongs to set k / 2):
  //  hardware:     one trigger, two frames. Written as TriggerSelector = FrameBurstStart with
  //                AcquisitionBurstFrameCount = 2 (SFNC); a camera without them is refused
  //                unless [cameras.features] sets TriggerSelector (a vendor double-shutter mode).
  //  two_triggers: TriggerSelector = FrameStart, one frame per trigger, two triggers a set.
  //  free_run:     TriggerMode = Off; frames are not tied to trigger events.
  config::FrameMode frame_mode = config::FrameMode::hardware;
  std::string trigger_source = "Line1";       // "Software" for software triggers
  std::string trigger_activation = "RisingEdge";  // the plan's edges; not written for Software
  std::optional<double> exposure_time_us;     // ExposureTime (or ExposureTimeAbs), read back
  // A trigger the camera took whose frame has not begun to arrive this long after marks the
  // camera disconnected (the camera, its cable or its stream is gone), as does the Aravis
  // "control-lost" signal and a trigger command that fails.
  std::chrono::milliseconds frame_timeout{400};
  // Software triggers: frames are matched to the trigger (and event) they answer by time
  // (TriggerMatcher) within this tolerance, below half the closest spacing of two triggers;
  // 0: frames are counted instead (frame k of the stream is set k / 2 since start).
  std::int64_t match_tolerance_ns = 0;
  // frame_mode hardware with match_tolerance_ns: frame B's time after frame A's by the plan, so
  // the frames' roles come from time (TriggerMatcher), not from the frame counter's parity alone.
  std::int64_t burst_separation_ns = 0;
  // frame_mode two_triggers with software triggers: the camera's readout time (the plan's
  // readout_us; 0: unknown). A camera that takes a trigger only at the end of its readout (a
  // frame grid, like Aravis's GigE fake) answers it at the next grid line: a trigger sent just
  // before one moves a whole readout later with the smallest host delay, and its pair is lost.
  // Once the camera has answered 8 triggers and the quickest answer came within half the
  // readout, the camera's triggers are sent that latency plus an eighth of the readout later,
  // just after the grid line: a delay then has most of a readout to spare (trigger_phase.h).
  std::int64_t readout_ns = 0;
  int packet_size = 0;                      // GigE GevSCPSPacketSize in bytes; 0: camera's value
  int socket_buffer_bytes = 0;              // GigE receive socket buffer; 0: Aravis default
  // GigE: how long an incomplete frame waits for missing packets before it fails (Aravis
  // "frame-retention"); 0: Aravis default. Shorter reports losses sooner.
  int frame_retention_us = 0;
  int buffer_count = 16;                    // frames in the buffer pool (>= 2)
  // Counter of the camera's frame ids: GigE Vision 1.x sends 16-bit ids that skip 0.
  int frame_id_bits = 16;
  bool frame_id_zero_reserved = true;
  // The frame id the camera gives its first frame after AcquisitionStart (GigE Vision
  // cameras usually restart at 1). nullopt: the first id received is frame A of set 0, which
  // swaps A and B for the whole run if that very first frame is lost entirely.
  std::optional<std::uint64_t> first_frame_id;
  // Called from the delivery thread for every frame the stream gave up on (missing packets,
  // timeout, size mismatch, unsupported pixel format), with its unwrapped frame number. Such
  // a frame is never delivered; this lets a status display (or a test) see each loss at once.
  std::function<void(std::uint64_t frame_id)> on_failed_frame;
};

class AravisCamera final : public Camera {
 public:
  AravisCamera(std::string id, AravisCameraOptions options = {});
  // A camera reached another way (a GenTL producer): see make_gentl_camera.
  AravisCamera(std::string id, AravisCameraOptions options, std::unique_ptr<detail::CameraBackend> backend);
  ~AravisCamera() override;

  const std::string& id() const override;
  // Opens config.device_id (an Aravis device id, serial-based id or IP address) and applies
  // PixelFormat, the ROI (Width, Height, OffsetX, OffsetY), AcquisitionMode, the frame mode
  // (TriggerSelector, TriggerMode, TriggerSource, TriggerActivation), ExposureTime, packet
  // size and then every [cameras.features] entry; each value is read back.
  // Throws runtime_error naming the camera and listing the devices found when the device is
  // absent; bad_input naming the camera and the GenICam feature when a feature is unknown or
  // a value is not accepted or comes back changed.
  void configure(const config::CameraConfig& config) override;
  void start(FrameSink sink) override;
  void stop() override;
  StreamStatistics statistics() const override;
  bool connected() const override;
  std::string connection_problem() const override;

  // Sends one TriggerSoftware command (for trigger_source = "Software") and waits for the
  // camera's answer. Throws runtime_error (and marks the camera disconnected) if it fails.
  void software_trigger();
  // Queues the TriggerSoftware commands of trigger event `event` for the camera's trigger
  // thread and returns at once, so a camera that stopped answering cannot hold up the others:
  // one (hardware), or two `spacing_ns` apart from when the first was sent (two_triggers).
  // With match_tolerance_ns its frames carry `event` as trigger index. nullopt: one warm-up
  // trigger whose frames are discarded. Ignored once disconnected. Needs start().
  void request_software_trigger(std::optional<std::uint64_t> event, std::int64_t spacing_ns = 0);
  // Frames no trigger explained (matching by time), discarded.
  std::uint64_t frames_unmatched() const;
  // Tells the camera a hardware trigger line fired for it, so a frame that never comes is
  // noticed (frame_timeout).
  void note_hardware_trigger();
  // Trigger pulses the camera needs per double-frame set: 1 (hardware), 2 (two_triggers),
  // 0 (free_run).
  int triggers_per_set() const;
  // Bytes of one frame as the configured camera reports them (0 before configure()).
  std::size_t payload_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Device ids Aravis currently sees ("Aravis-Fake-GVA (127.0.0.2)"), for messages and tools.
std::vector<std::string> list_aravis_devices();

}  // namespace tomorig::acquisition
