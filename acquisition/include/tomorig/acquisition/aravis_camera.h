#pragma once
// A GenICam camera (GigE Vision or USB3 Vision) through Aravis 0.8. Aravis and GLib stay in
// src/; this header only names the options.
//
//   AravisCameraOptions opt;  opt.trigger_source = "Software";
//   AravisCamera cam("cam0", opt);
//   cam.configure(rig.cameras[0]);     // opens config.device_id, applies the features
//   cam.start([&](CameraFrame&& f) { assembler.add_frame(0, std::move(f)); });
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/acquisition/camera.h"

namespace tomorig::acquisition {

// How the camera produces the two frames of a set. Either way frames alternate A, B, A, B...
// so frame k of the stream belongs to set k / 2.
enum class DoubleFrameMode : std::uint8_t {
  double_frame,  // the camera takes two frames per trigger (PIV double-shutter cameras)
  two_triggers,  // the camera takes one frame per trigger and is triggered twice per set
};

struct AravisCameraOptions {
  // GenICam settings applied by configure(), before the [cameras.features] of the
  // configuration (which may override any of them). Empty strings leave the camera's value.
  std::string acquisition_mode = "Continuous";
  std::string trigger_mode = "On";          // FrameStart trigger; "Off": free running
  std::string trigger_source = "Line1";     // "Software" for software triggers
  std::optional<double> exposure_time_us;   // ExposureTime (or ExposureTimeAbs)
  int packet_size = 0;                      // GigE GevSCPSPacketSize in bytes; 0: camera's value
  int socket_buffer_bytes = 0;              // GigE receive socket buffer; 0: Aravis default
  // GigE: how long an incomplete frame waits for missing packets before it fails (Aravis
  // "frame-retention"); 0: Aravis default. Shorter reports losses sooner.
  int frame_retention_us = 0;
  DoubleFrameMode mode = DoubleFrameMode::double_frame;
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
  ~AravisCamera() override;

  const std::string& id() const override;
  // Opens config.device_id (an Aravis device id, serial-based id or IP address) and applies
  // PixelFormat, the ROI (Width, Height, OffsetX, OffsetY), AcquisitionMode, TriggerMode,
  // TriggerSource, ExposureTime, packet size and then every [cameras.features] entry.
  // Throws runtime_error naming the camera and listing the devices found when the device is
  // absent; bad_input naming the camera and the GenICam feature when a feature is unknown or
  // a value is not accepted.
  void configure(const config::CameraConfig& config) override;
  void start(FrameSink sink) override;
  void stop() override;
  StreamStatistics statistics() const override;

  // Sends one TriggerSoftware command (for trigger_source = "Software").
  void software_trigger();
  // Trigger pulses the camera needs per double-frame set: 1 (double_frame) or 2 (two_triggers).
  int triggers_per_set() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Device ids Aravis currently sees ("Aravis-Fake-GVA (127.0.0.2)"), for messages and tools.
std::vector<std::string> list_aravis_devices();

}  // namespace tomorig::acquisition
