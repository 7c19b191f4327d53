#include "tomorig/acquisition/aravis_camera.h"

#include <arpa/inet.h>
#include <arv.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstring>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include "camera_backend.h"
#include "genicam_features.h"
#include "glib_handles.h"
#include "tomorig/acquisition/frame_id.h"
#include "tomorig/acquisition/trigger_matcher.h"
#include "tomorig/acquisition/trigger_phase.h"
#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

using detail::GErrorSlot;
using detail::GObjectPtr;

// How often the delivery thread checks for stop() and lost frames.
constexpr std::chrono::microseconds kPopTimeout{50'000};
// A trigger whose frame is this much later than the camera's usual answer gets one nudge (a
// register read, see await_answer()); the answer latency is the median of the last few.
constexpr std::int64_t kNudgeMarginNs = 3'000'000;
// Not within this much of the camera's next trigger: the nudge would come too late to matter.
constexpr std::int64_t kNudgeGuardNs = 5'000'000;
constexpr std::size_t kLatenciesKept = 16;
constexpr std::size_t kLatenciesNeeded = 4;
// Answers seen before the trigger phase is judged against the readout (two_triggers).
constexpr std::size_t kLatenciesForPhase = 8;
// GigE Vision bootstrap register CCP (control channel privilege): reading it changes nothing,
// and every GigE Vision camera answers it (Aravis's heartbeat reads it too).
constexpr guint32 kGvControlChannelPrivilege = 0x0A00;

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

namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int frames_per_trigger(config::FrameMode mode) { return mode == config::FrameMode::hardware ? 2 : 1; }

}  // namespace

struct AravisCamera::Impl {
  std::string id;
  AravisCameraOptions options;
  std::unique_ptr<detail::CameraBackend> backend;
  config::CameraConfig config;
  GObjectPtr<ArvCamera> camera;
  gulong control_lost_handler = 0;

  // Connection watch: every trigger the camera took is remembered until the first packet of
  // its frame arrives; one left unanswered for options.frame_timeout means the camera is gone.
  mutable std::mutex watch_mutex;
  std::deque<std::int64_t> unanswered_triggers;  // steady-clock times, oldest first
  std::uint64_t triggers_taken = 0;
  std::uint64_t triggers_answered = 0;
  std::atomic<bool> disconnected{false};
  std::string problem;  // guarded by watch_mutex

  // The trigger thread sends queued TriggerSoftware commands, so a dead camera (whose every
  // command waits for GVCP timeouts) never holds up the rig loop or the other cameras.
  struct TriggerJob {
    std::optional<std::uint64_t> event;  // nullopt: warm-up, one trigger, its frames discarded
    std::int64_t spacing_ns = 0;         // two_triggers: frame B's trigger after frame A's
  };
  std::mutex trigger_mutex;
  std::condition_variable trigger_wanted;  // a job queued, a frame arrived, or stop
  std::deque<TriggerJob> trigger_jobs;
  std::thread trigger_thread;
  // Frames that arrived (any status), when the last one did: the trigger thread's view of
  // whether its last trigger was answered. Guarded by trigger_mutex.
  std::uint64_t frames_arrived = 0;
  std::int64_t last_arrival_ns = 0;
  std::deque<std::int64_t> answer_latencies;  // trigger thread only: trigger sent -> frame arrived
  // Trigger thread only: how much later than asked each job's triggers go out (readout_ns).
  std::int64_t phase_delay_ns = 0;
  bool phase_judged = false;
  std::atomic<std::uint64_t> nudges{0};
  // GigE Vision: a socket of our own for the nudge's GVCP packet, sent without waiting for an
  // answer, so a nudge never holds up the camera's next trigger (-1: no nudges).
  int nudge_socket = -1;
  sockaddr_in nudge_to{};
  std::uint16_t nudge_request = 0;
  void open_nudge_socket();
  void close_nudge_socket();
  // Software triggers: which trigger each frame answers, by time (null: frames are counted).
  std::unique_ptr<TriggerMatcher> matcher;
  std::atomic<std::uint64_t> unmatched{0};

  std::shared_ptr<detail::FrameStream> pool;  // kept after stop() so statistics stay readable
  mutable std::mutex pool_mutex;  // guards the `pool` pointer for statistics() (sinks may call it)
  std::size_t payload = 0;

  std::mutex mutex;  // guards start/stop/configure against each other
  std::thread delivery;
  std::atomic<bool> running{false};
  FrameSink sink;
  std::atomic<std::uint64_t> delivered{0};
  std::atomic<std::uint64_t> frame_id_gaps{0};
  std::atomic<std::uint64_t> rejected{0};  // complete buffers refused (size, pixel format)

  void open(const config::CameraConfig& cfg);
  void apply(const config::CameraConfig& cfg);
  void apply_frame_mode(ArvDevice* device, const config::CameraConfig& cfg);
  void deliver_loop();
  void deliver(const detail::StreamBuffer& buffer, FrameIdUnwrapper& unwrapper);
  void trigger_loop();
  void frame_arrived();
  void await_answer(std::int64_t sent_ns, std::uint64_t arrivals_before, std::optional<std::int64_t> deadline_ns,
                    bool learn);
  void nudge();
  std::optional<std::int64_t> median_answer_latency() const;
  void judge_trigger_phase();
  bool send_trigger();  // false: the command failed and the camera is marked disconnected
  void trigger_taken();
  void frames_seen(std::uint64_t sequence);
  void check_unanswered();
  void mark_disconnected(std::string why);
  void forget_camera();
  static void on_control_lost(ArvDevice*, gpointer data);
};

void AravisCamera::Impl::mark_disconnected(std::string why) {
  std::lock_guard lock(watch_mutex);
  if (disconnected) return;
  problem = std::move(why);
  disconnected = true;
}

void AravisCamera::Impl::trigger_taken() {
  std::lock_guard lock(watch_mutex);
  ++triggers_taken;
  unanswered_triggers.push_back(steady_ns());
}

// Frame `sequence` (0-based since start) began to arrive: the triggers up to it are answered.
void AravisCamera::Impl::frames_seen(std::uint64_t sequence) {
  const std::uint64_t per_trigger = static_cast<std::uint64_t>(frames_per_trigger(options.frame_mode));
  const std::uint64_t answered = sequence / per_trigger + 1;
  // A camera that merged two triggers into one frame (Aravis's GigE fake does, see
  // await_answer()) leaves the count one trigger behind for good; a few such and the oldest
  // "unanswered" trigger would be older than the frame timeout although frames keep coming.
  // A frame arriving says the camera is alive: triggers sent long before it are answered.
  const std::int64_t stale = steady_ns() - std::chrono::nanoseconds(options.frame_timeout).count() / 2;
  std::lock_guard lock(watch_mutex);
  while (!unanswered_triggers.empty() && (triggers_answered < answered || unanswered_triggers.front() < stale)) {
    unanswered_triggers.pop_front();
    ++triggers_answered;
  }
}

void AravisCamera::Impl::check_unanswered() {
  std::int64_t oldest = 0;
  {
    std::lock_guard lock(watch_mutex);
    if (unanswered_triggers.empty() || disconnected) return;
    oldest = unanswered_triggers.front();
  }
  const std::int64_t waited = steady_ns() - oldest;
  if (waited > std::chrono::nanoseconds(options.frame_timeout).count())
    mark_disconnected(fmt::format("no frame {} ms after a trigger it took (frame timeout {} ms): the camera, its cable "
                                  "or its stream is gone",
                                  waited / 1'000'000, options.frame_timeout.count()));
}

// The trigger counts from when it was asked for: a camera that died stops answering the
// command itself, and the watch must not wait for the command's own timeouts.
bool AravisCamera::Impl::send_trigger() {
  GErrorSlot error;
  arv_camera_software_trigger(camera.get(), error.out());
  if (error) {
    mark_disconnected(fmt::format("TriggerSoftware failed: {}", error.message()));
    return false;
  }
  return true;
}

void AravisCamera::Impl::frame_arrived() {
  {
    std::lock_guard lock(trigger_mutex);
    ++frames_arrived;
    last_arrival_ns = steady_ns();
  }
  trigger_wanted.notify_all();
}

void AravisCamera::Impl::open_nudge_socket() {
  close_nudge_socket();
  if (!camera || !arv_camera_is_gv_device(camera.get())) return;
  GSocketAddress* address = arv_gv_device_get_device_address(ARV_GV_DEVICE(arv_camera_get_device(camera.get())));
  if (address == nullptr || !G_IS_INET_SOCKET_ADDRESS(address)) return;
  gchar* text = g_inet_address_to_string(g_inet_socket_address_get_address(G_INET_SOCKET_ADDRESS(address)));
  nudge_to = sockaddr_in{};
  nudge_to.sin_family = AF_INET;
  nudge_to.sin_port = htons(3956);  // GVCP
  const bool parsed = text != nullptr && inet_pton(AF_INET, text, &nudge_to.sin_addr) == 1;
  g_free(text);
  if (parsed) nudge_socket = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
}

void AravisCamera::Impl::close_nudge_socket() {
  if (nudge_socket >= 0) ::close(nudge_socket);
  nudge_socket = -1;
}

// A GVCP READREG of the CCP register from a socket of our own, no acknowledgement asked for
// and none waited for: any command makes a camera that polls its control socket look at its
// state again (see await_answer()); it triggers nothing and changes nothing (reads are open to
// any host). Answers that come anyway (the fake answers every command) are drained and dropped.
void AravisCamera::Impl::nudge() {
  if (nudge_socket < 0) return;
  if (++nudge_request == 0) nudge_request = 1;  // GVCP request ids are never 0
  const std::uint32_t address = htonl(kGvControlChannelPrivilege);
  unsigned char packet[12] = {0x42, 0x00, 0x00, 0x80, 0x00, 0x04,  // key, flags (no ack), READREG_CMD, length 4
                              static_cast<unsigned char>(nudge_request >> 8), static_cast<unsigned char>(nudge_request & 0xff)};
  std::memcpy(packet + 8, &address, sizeof address);
  ::sendto(nudge_socket, packet, sizeof packet, 0, reinterpret_cast<const sockaddr*>(&nudge_to), sizeof nudge_to);
  unsigned char drain[64];
  while (::recv(nudge_socket, drain, sizeof drain, 0) > 0) {
  }
  ++nudges;
}

// Waits for the frame of the trigger sent at `sent_ns` (the first frame to arrive after it)
// until `deadline_ns` (the next trigger of this job), else until the next job is queued or the
// frame timeout. A camera answers its triggers with a steady latency (a fixed phase of its
// readout); one whose frame is kNudgeMarginNs later than the median of its last answers gets
// one register read. Aravis's GigE fake needs it: it looks for a latched software trigger
// only on its 40 ms grid, and now and then sleeps through a grid line (its poll timeout is
// computed unsigned, and a clock tick between two reads of the time turns it into 100 ms), so
// the latched trigger waits for the next packet to arrive: the next trigger, which it then
// merges with this one (one frame for two triggers: a frame lost), or nothing for 100 ms (a
// frame far off its trigger). Any GVCP command wakes it; the read makes the frame ~3 ms late
// instead of lost. For a camera that answered, nothing is sent.
std::optional<std::int64_t> AravisCamera::Impl::median_answer_latency() const {
  if (answer_latencies.size() < kLatenciesNeeded) return std::nullopt;
  std::vector<std::int64_t> sorted(answer_latencies.begin(), answer_latencies.end());
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  return sorted[sorted.size() / 2];
}

// Once per run (see AravisCameraOptions::readout_ns and trigger_phase.h): a two-trigger camera
// whose quickest answer came sooner than half its readout gets its triggers just past its grid
// line instead of before it. A camera without a grid answers at the same latency either way; it
// only triggers that much later, once.
void AravisCamera::Impl::judge_trigger_phase() {
  if (phase_judged || options.frame_mode != config::FrameMode::two_triggers || options.readout_ns <= 0 ||
      answer_latencies.size() < kLatenciesForPhase)
    return;
  phase_judged = true;
  phase_delay_ns = trigger_phase_delay_ns(answer_latencies, options.readout_ns);
  if (phase_delay_ns == 0) return;
  // A new regime: the nudge learns the latency again, and the matcher the camera's offset (on
  // a grid camera it grows by most of a readout; a stale offset would let a frame that crossed
  // a grid line pass for the next trigger's).
  answer_latencies.clear();
  if (matcher) matcher->relearn_offsets();
}

void AravisCamera::Impl::await_answer(std::int64_t sent_ns, std::uint64_t arrivals_before,
                                      std::optional<std::int64_t> deadline_ns, bool learn) {
  std::optional<std::int64_t> nudge_at;
  if (const auto latency = median_answer_latency()) nudge_at = sent_ns + *latency + kNudgeMarginNs;
  const std::int64_t cap = deadline_ns ? *deadline_ns : sent_ns + std::chrono::nanoseconds(options.frame_timeout).count();
  bool nudged = false;
  std::unique_lock lock(trigger_mutex);
  auto answered = [&] { return frames_arrived > arrivals_before; };
  auto next_job_waits = [&] { return !deadline_ns && !trigger_jobs.empty(); };
  while (running && !disconnected && !answered() && !next_job_waits()) {
    const std::int64_t now = steady_ns();
    if (now >= cap) break;
    if (nudge_at && !nudged && now >= *nudge_at) {
      nudged = true;
      if (cap - now > kNudgeGuardNs) {
        lock.unlock();
        nudge();
        lock.lock();
      }
      continue;
    }
    const std::int64_t wake = nudge_at && !nudged ? std::min(cap, *nudge_at) : cap;
    trigger_wanted.wait_until(lock, std::chrono::steady_clock::time_point(std::chrono::nanoseconds(wake)),
                              [&] { return !running || answered() || next_job_waits(); });
  }
  // Latencies of nudged answers would teach the nudge's own delay.
  if (learn && !nudged && answered() && last_arrival_ns >= sent_ns) {
    answer_latencies.push_back(last_arrival_ns - sent_ns);
    if (answer_latencies.size() > kLatenciesKept) answer_latencies.pop_front();
  }
}

// One job per trigger event: frame A's trigger, and for two_triggers frame B's, spaced from
// when A's was really sent (not when it was asked for), so a busy host delays both alike.
// Between triggers the thread watches for each trigger's frame (await_answer()).
void AravisCamera::Impl::trigger_loop() {
  for (;;) {
    TriggerJob job;
    {
      std::unique_lock lock(trigger_mutex);
      trigger_wanted.wait(lock, [&] { return !trigger_jobs.empty() || !running; });
      if (!running) return;
      job = trigger_jobs.front();
      trigger_jobs.pop_front();
    }
    const int triggers = job.event && options.frame_mode == config::FrameMode::two_triggers ? 2 : 1;
    judge_trigger_phase();
    if (job.event && phase_delay_ns > 0) {
      std::unique_lock lock(trigger_mutex);
      trigger_wanted.wait_for(lock, std::chrono::nanoseconds(phase_delay_ns), [&] { return !running; });
      if (!running) return;
    }
    std::int64_t frame_a_sent = 0;
    std::int64_t sent = 0;
    std::uint64_t arrivals = 0;
    for (int k = 0; k < triggers && !disconnected && running; ++k) {
      if (k == 1) {
        await_answer(sent, arrivals, frame_a_sent + job.spacing_ns, true);
        std::this_thread::sleep_until(std::chrono::steady_clock::time_point(std::chrono::nanoseconds(frame_a_sent + job.spacing_ns)));
      }
      {
        std::lock_guard lock(trigger_mutex);
        arrivals = frames_arrived;
      }
      sent = steady_ns();
      if (k == 0) frame_a_sent = sent;
      if (matcher) matcher->expect({job.event, k == 0 ? Exposure::A : Exposure::B, sent});
      trigger_taken();
      send_trigger();
    }
    // The warm-up frame answers late (a camera not ready yet): it teaches no latency.
    if (running && !disconnected) await_answer(sent, arrivals, std::nullopt, job.event.has_value());
  }
}

void AravisCamera::Impl::on_control_lost(ArvDevice*, gpointer data) {
  static_cast<Impl*>(data)->mark_disconnected("Aravis reported control-lost (heartbeat unanswered)");
}

void AravisCamera::Impl::forget_camera() {
  if (camera && control_lost_handler != 0)
    g_signal_handler_disconnect(arv_camera_get_device(camera.get()), control_lost_handler);
  control_lost_handler = 0;
  camera.reset();
}

void AravisCamera::Impl::open(const config::CameraConfig& cfg) {
  camera.reset(backend->open(id, cfg));
  control_lost_handler =
      g_signal_connect(arv_camera_get_device(camera.get()), "control-lost", G_CALLBACK(on_control_lost), this);
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
  apply_frame_mode(device, cfg);
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

  payload = backend->payload(camera.get(), id);
}

// The frame mode as GenICam (SFNC) features. A double-frame ("hardware") camera answers one
// trigger with two frames: SFNC says FrameBurstStart with a burst of 2. A camera offering
// neither is taken for a single-frame camera and refused, unless the rig file sets
// TriggerSelector itself (a vendor double-shutter mode, configured in [cameras.features]).
void AravisCamera::Impl::apply_frame_mode(ArvDevice* device, const config::CameraConfig& cfg) {
  const bool selector = detail::has_feature(device, "TriggerSelector");
  auto select = [&](const std::string& what) {
    if (selector) detail::set_feature(device, id, "TriggerSelector", what);
  };
  if (options.frame_mode == config::FrameMode::free_run) {
    select("FrameStart");
    detail::set_feature(device, id, "TriggerMode", "Off");
    return;
  }
  if (options.frame_mode == config::FrameMode::hardware) {
    const auto selectors = detail::enumeration_entries(device, "TriggerSelector");
    const bool burst = std::find(selectors.begin(), selectors.end(), "FrameBurstStart") != selectors.end() &&
                       detail::has_feature(device, "AcquisitionBurstFrameCount");
    if (burst) {
      select("FrameStart");  // only the burst trigger starts frames
      detail::set_feature(device, id, "TriggerMode", "Off");
      select("FrameBurstStart");
      detail::set_feature(device, id, "AcquisitionBurstFrameCount", "2");
    } else if (!cfg.features.count("TriggerSelector")) {
      throw bad_input(fmt::format(
          "camera {}: frame_mode = \"hardware\" needs a camera that takes two frames per trigger, but GenICam feature "
          "TriggerSelector offers no FrameBurstStart (it offers: {}) and there is no AcquisitionBurstFrameCount: this "
          "is a single-frame camera. Set frame_mode = \"two_triggers\" (with [trigger.camera] readout_us), or, for a "
          "double-shutter camera with a vendor mode, set that mode and TriggerSelector in [cameras.features]",
          id, selectors.empty() ? std::string("nothing") : fmt::format("{}", fmt::join(selectors, ", "))));
    } else {
      select("FrameStart");  // [cameras.features] chooses the selector and the vendor mode after this
    }
  } else {
    select("FrameStart");
  }
  detail::set_feature(device, id, "TriggerMode", "On");
  detail::set_feature(device, id, "TriggerSource", options.trigger_source);
  // The plan's edges rise; a software trigger has no edge, and some cameras lock the feature then.
  if (options.trigger_source != "Software" && !options.trigger_activation.empty())
    detail::set_feature(device, id, "TriggerActivation", options.trigger_activation);
  else if (!options.trigger_activation.empty() && detail::feature_available(device, "TriggerActivation"))
    detail::set_feature(device, id, "TriggerActivation", options.trigger_activation);
}

void AravisCamera::Impl::deliver(const detail::StreamBuffer& buffer, FrameIdUnwrapper& unwrapper) {
  const std::uint64_t raw_id = buffer.frame_id;
  if (raw_id == 0 && options.frame_id_zero_reserved) {  // failed before any packet said which frame
    pool->give_back(buffer.token);
    return;
  }
  frame_arrived();  // complete or not, stale or not: the camera answered a trigger
  const auto sequence = unwrapper.unwrap(raw_id);
  frame_id_gaps = unwrapper.gaps();
  if (sequence) frames_seen(*sequence);  // failed or not, the camera answered its trigger
  // Incomplete or corrupt buffers still move the frame-id sequence (so later frames keep
  // their A/B role) but are never delivered: the stream counts them as failures.
  if (!sequence) {  // stale or duplicate id: not a frame of this acquisition's sequence
    pool->give_back(buffer.token);
    return;
  }
  auto reject = [&] {
    pool->give_back(buffer.token);
    if (options.on_failed_frame) options.on_failed_frame(*sequence);
  };
  if (!buffer.complete) {
    reject();
    return;
  }
  const auto type = buffer.type;
  const int width = buffer.width;
  const int height = buffer.height;
  if (!type || width <= 0 || height <= 0 || buffer.data == nullptr ||
      buffer.size < static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * bytes_per_sample(*type)) {
    ++rejected;  // the stream saw a good buffer; tomorig cannot use it, so it is a failure too
    reject();
    return;
  }
  CameraFrame frame;
  frame.frame_id = *sequence;
  frame.trigger_index = *sequence / 2;
  frame.exposure = *sequence % 2 == 0 ? Exposure::A : Exposure::B;
  frame.timestamp_ns = buffer.timestamp_ns;
  if (matcher) {
    // The camera numbers frames, not events: the trigger it answers is found by time.
    // Double-frame bursts alternate A, B in the frame counter: that says which frame this is
    // when its partner was lost; the matcher finds the trigger by time.
    const std::optional<Exposure> burst_position =
        options.frame_mode == config::FrameMode::hardware ? std::optional(frame.exposure) : std::nullopt;
    const auto hit = matcher->match(*sequence, frame.timestamp_ns, burst_position);
    if (!hit || !hit->event) {  // a warm-up frame, or one no trigger explains
      if (!hit) ++unmatched;
      pool->give_back(buffer.token);
      return;
    }
    frame.trigger_index = *hit->event;
    frame.exposure = hit->exposure;
  }
  frame.image = Image::view(const_cast<void*>(buffer.data), width, height, *type, 0, pool->lease(buffer.token));
  ++delivered;
  sink(std::move(frame));
}

void AravisCamera::Impl::deliver_loop() {
  FrameIdUnwrapper unwrapper(options.frame_id_bits, options.frame_id_zero_reserved);
  if (options.first_frame_id) unwrapper.expect_first(*options.first_frame_id);
  while (running) {
    if (const auto buffer = pool->pop(kPopTimeout)) deliver(*buffer, unwrapper);
    check_unanswered();
  }
}

AravisCamera::AravisCamera(std::string id, AravisCameraOptions options)
    : AravisCamera(std::move(id), std::move(options), detail::make_aravis_backend()) {}

AravisCamera::AravisCamera(std::string id, AravisCameraOptions options, std::unique_ptr<detail::CameraBackend> backend)
    : impl_(std::make_unique<Impl>()) {
  impl_->backend = std::move(backend);
  if (id.empty()) throw bad_input("aravis camera: the camera id is empty");
  if (options.buffer_count < 2)
    throw bad_input(fmt::format("camera {}: buffer_count = {}: must be >= 2", id, options.buffer_count));
  if (options.packet_size < 0 || options.socket_buffer_bytes < 0 || options.frame_retention_us < 0)
    throw bad_input(fmt::format("camera {}: packet size, socket buffer and frame retention must be >= 0", id));
  impl_->id = std::move(id);
  impl_->options = std::move(options);
  FrameIdUnwrapper check(impl_->options.frame_id_bits, impl_->options.frame_id_zero_reserved);  // validates
}

AravisCamera::~AravisCamera() {
  stop();
  impl_->close_nudge_socket();
  impl_->forget_camera();
}

const std::string& AravisCamera::id() const { return impl_->id; }

int AravisCamera::triggers_per_set() const {
  switch (impl_->options.frame_mode) {
    case config::FrameMode::hardware: return 1;
    case config::FrameMode::two_triggers: return 2;
    case config::FrameMode::free_run: return 0;
  }
  return 1;
}

std::size_t AravisCamera::payload_bytes() const { return impl_->payload; }

void AravisCamera::configure(const config::CameraConfig& config) {
  std::lock_guard lock(impl_->mutex);
  if (impl_->running) throw runtime_error(fmt::format("camera {}: cannot configure while running; stop it first", impl_->id));
  if (config.backend != impl_->backend->kind())
    throw bad_input(fmt::format("camera {}: backend is '{}', but a '{}' camera was asked to take it", impl_->id,
                                config::to_string(config.backend), config::to_string(impl_->backend->kind())));
  if (!impl_->camera || config.device_id != impl_->config.device_id || config.producer != impl_->config.producer) {
    impl_->forget_camera();
    impl_->open(config);
  }
  impl_->config = config;
  impl_->apply(config);
}

void AravisCamera::start(FrameSink sink) {
  if (!sink) throw bad_input(fmt::format("camera {}: start() needs a frame sink", impl_->id));
  std::lock_guard lock(impl_->mutex);
  if (impl_->running) return;
  if (!impl_->camera) throw runtime_error(fmt::format("camera {}: start() before configure()", impl_->id));
  {
    auto stream = impl_->backend->open_stream(impl_->camera.get(), impl_->payload, impl_->options, impl_->id);
    std::lock_guard pool_lock(impl_->pool_mutex);
    impl_->pool = std::move(stream);
  }
  GErrorSlot error;
  impl_->sink = std::move(sink);
  impl_->delivered = 0;
  impl_->frame_id_gaps = 0;
  impl_->rejected = 0;
  {
    std::lock_guard watch(impl_->watch_mutex);
    impl_->unanswered_triggers.clear();
    impl_->triggers_taken = impl_->triggers_answered = 0;
  }
  impl_->trigger_jobs.clear();
  impl_->frames_arrived = 0;
  impl_->last_arrival_ns = 0;
  impl_->answer_latencies.clear();
  impl_->phase_delay_ns = 0;
  impl_->phase_judged = false;
  impl_->nudges = 0;
  impl_->unmatched = 0;
  if (impl_->options.trigger_source == "Software" && impl_->options.match_tolerance_ns > 0 &&
      impl_->options.frame_mode != config::FrameMode::free_run)
    impl_->matcher = std::make_unique<TriggerMatcher>(frames_per_trigger(impl_->options.frame_mode),
                                                      impl_->options.match_tolerance_ns,
                                                      impl_->options.frame_mode == config::FrameMode::hardware
                                                          ? impl_->options.burst_separation_ns
                                                          : 0);
  else
    impl_->matcher.reset();
  impl_->open_nudge_socket();
  impl_->running = true;
  impl_->delivery = std::thread([impl = impl_.get()] { impl->deliver_loop(); });
  impl_->trigger_thread = std::thread([impl = impl_.get()] { impl->trigger_loop(); });
  arv_camera_start_acquisition(impl_->camera.get(), error.out());
  if (error) {
    impl_->running = false;
    impl_->trigger_wanted.notify_all();
    impl_->delivery.join();
    impl_->trigger_thread.join();
    impl_->close_nudge_socket();
    throw runtime_error(fmt::format("camera {}: AcquisitionStart failed: {}", impl_->id, error.message()));
  }
}

void AravisCamera::stop() {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->running) return;
  {
    std::lock_guard trigger_lock(impl_->trigger_mutex);
    impl_->running = false;
  }
  impl_->trigger_wanted.notify_all();
  if (impl_->delivery.joinable()) impl_->delivery.join();
  if (impl_->trigger_thread.joinable()) impl_->trigger_thread.join();
  // A camera known to be gone would make AcquisitionStop wait out every GVCP retry.
  GErrorSlot error;
  if (impl_->camera && !impl_->disconnected) arv_camera_stop_acquisition(impl_->camera.get(), error.out());
  {
    std::lock_guard pool_lock(impl_->pool_mutex);
    if (impl_->pool) impl_->pool->stop();
  }
  impl_->close_nudge_socket();
  impl_->sink = nullptr;
}

void AravisCamera::software_trigger() {
  if (!impl_->camera) throw runtime_error(fmt::format("camera {}: software trigger before configure()", impl_->id));
  impl_->trigger_taken();
  if (!impl_->send_trigger())
    throw runtime_error(fmt::format("camera {}: {}", impl_->id, connection_problem()));
}

void AravisCamera::request_software_trigger(std::optional<std::uint64_t> event, std::int64_t spacing_ns) {
  if (!impl_->running) throw runtime_error(fmt::format("camera {}: software trigger requested before start()", impl_->id));
  if (impl_->disconnected) return;
  {
    std::lock_guard lock(impl_->trigger_mutex);
    impl_->trigger_jobs.push_back({event, spacing_ns});
  }
  impl_->trigger_wanted.notify_one();
}

std::uint64_t AravisCamera::frames_unmatched() const { return impl_->unmatched; }

void AravisCamera::note_hardware_trigger() { impl_->trigger_taken(); }

bool AravisCamera::connected() const { return !impl_->disconnected; }

std::string AravisCamera::connection_problem() const {
  std::lock_guard lock(impl_->watch_mutex);
  return impl_->problem;
}

StreamStatistics AravisCamera::statistics() const {
  StreamStatistics s;
  s.delivered = impl_->delivered;
  s.frame_id_gaps = impl_->frame_id_gaps;
  std::shared_ptr<detail::FrameStream> pool;
  {
    std::lock_guard pool_lock(impl_->pool_mutex);
    pool = impl_->pool;
  }
  if (!pool) return s;
  const detail::StreamCounters c = pool->counters();
  s.completed = c.completed;
  s.failures = c.failures + impl_->rejected;
  s.underruns = c.underruns;
  s.resends = c.resends;
  s.missing_packets = c.missing_packets;
  return s;
}

}  // namespace tomorig::acquisition
