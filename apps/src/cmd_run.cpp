// tomorig run: the main job. Trigger device, cameras and recorder in one process:
//
//   trigger -> cameras -> FrameSetAssembler -> (sender thread) inproc PUSH -> PULL -> recorder
//
// The recorder is the same stream consumer a separate `tomorig record` would be, so the
// in-process rig and the split rig (tomorig acquire + tomorig record) share one data path.
// With no arguments it runs the embedded simulated 4-camera tpiv-thesis rig.
#include <atomic>
#include <cerrno>
#include <chrono>
#include <ctime>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <zmq.hpp>

#include "commands.h"
#include "record_layout.h"
#include "rig_acquisition.h"
#include "rig_status.h"
#include "stop_signal.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::app {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr const char* kInprocEndpoint = "inproc://tomorig-run";

struct RunOptions {
  std::string config_path;
  std::string out;
  std::optional<std::uint64_t> sets;
  std::optional<double> duration_s;
  std::string compression = "none";
  bool overwrite = false;
  std::string pace = "real-time";
  std::string on_camera_loss = "stop";
  std::vector<std::string> faults;
  std::string status = "tcp://127.0.0.1:5556";
  double disk_reserve_mb = 64.0;
};

std::filesystem::path default_output_path() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc);
  return std::filesystem::path("runs") / fmt::format("session-{}.h5", stamp);
}

trigger::Pacing parse_pace(const std::string& text) {
  if (text == "real-time") return trigger::Pacing::real_time;
  if (text == "max") return trigger::Pacing::as_fast_as_consumed;
  throw bad_input(fmt::format("--pace {} is not supported: use real-time or max", text));
}

// Moves assembled sets from the rig into the lossless stream on its own thread, so the
// recorder (the main thread) and the acquisition loop never wait on each other directly:
// ZeroMQ's queue between them is the back-pressure. Destruction stops and joins it.
class StreamPump {
 public:
  StreamPump(RigAcquisition& rig, stream::FrameSender& sender)
      : thread_([this, &rig, &sender] { pump(rig, sender); }) {}
  ~StreamPump() {
    abort_ = true;
    if (thread_.joinable()) thread_.join();
  }
  StreamPump(const StreamPump&) = delete;
  StreamPump& operator=(const StreamPump&) = delete;

  bool done() const { return done_; }
  void abort() { abort_ = true; }
  // Rethrows what ended the pump early, if anything (call after done()).
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  void pump(RigAcquisition& rig, stream::FrameSender& sender) {
    try {
      while (!abort_) {
        std::optional<FrameSet> set = rig.pop(100ms);
        if (!set) {
          if (rig.done()) break;
          continue;
        }
        while (!sender.send(*set))  // no room within the timeout: the recorder is busy
          if (abort_) break;
      }
    } catch (...) {
      error_ = std::current_exception();
    }
    done_ = true;
  }

  std::atomic<bool> abort_{false};
  std::atomic<bool> done_{false};
  std::exception_ptr error_;
  std::thread thread_;
};

std::string human_bytes(std::uintmax_t bytes) {
  if (bytes >= 1024 * 1024) return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  if (bytes >= 1024) return fmt::format("{:.1f} KiB", static_cast<double>(bytes) / 1024.0);
  return fmt::format("{} B", bytes);
}

void run(const RunOptions& opt) {
  config::RigConfig rig = opt.config_path.empty() ? config::default_rig_config()
                                                  : config::load_rig_config(opt.config_path);
  if (opt.sets && *opt.sets < 1) throw bad_input(fmt::format("--sets {} is invalid: must be >= 1", *opt.sets));
  const auto compression = storage::parse_compression(opt.compression);
  if (!compression)
    throw bad_input(fmt::format("--compression {} is not supported (none, bitshuffle-lz4)", opt.compression));
  const auto loss_policy = parse_camera_loss_policy(opt.on_camera_loss);
  if (!loss_policy)
    throw bad_input(fmt::format("--on-camera-loss {} is not supported: use stop or continue", opt.on_camera_loss));
  if (!(opt.disk_reserve_mb >= 0.0))
    throw bad_input(fmt::format("--disk-reserve-mb {:g} is invalid: it must be >= 0", opt.disk_reserve_mb));

  RigAcquisitionOptions acquisition;
  acquisition.sets = opt.sets;
  acquisition.duration_s = opt.duration_s;
  // A simulated rig records its configured number of sets unless told otherwise; a camera rig
  // runs until Ctrl-C.
  if (!opt.sets && !opt.duration_s && rig.simulation && rig.simulation->sets > 0)
    acquisition.sets = static_cast<std::uint64_t>(rig.simulation->sets);
  acquisition.pacing = parse_pace(opt.pace);
  acquisition.on_camera_loss = *loss_policy;
  for (const auto& fault : opt.faults) add_camera_fault(acquisition.faults, fault);
  acquisition.keep_truth = true;

  const std::filesystem::path out = opt.out.empty() ? default_output_path() : std::filesystem::path(opt.out);
  if (out.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(out.parent_path(), ec);
    if (ec)
      throw bad_input(fmt::format("cannot create the output folder {}: {}; choose another --out",
                                  out.parent_path().string(), ec.message()));
  }
  if (std::filesystem::exists(out) && !opt.overwrite)
    throw bad_input(fmt::format("{} exists; choose another --out or pass --overwrite", out.string()));

  // Builds, configures and arms everything: a bad rig fails here, before a file exists.
  RigAcquisition rig_run(rig, acquisition);

  storage::SessionInfo info;
  info.cameras = rig_run.session_cameras();
  info.rig_config_toml = rig.source_text;
  info.software_version = std::string(software_version());
  storage::SessionWriterOptions writer_options;
  writer_options.live = true;
  writer_options.compression = *compression;
  writer_options.overwrite = opt.overwrite;
  writer_options.disk_reserve_bytes = static_cast<std::uint64_t>(opt.disk_reserve_mb * 1e6);
  std::unique_ptr<storage::SessionWriter> writer;
  auto open_writer = [&] {
    writer = std::make_unique<storage::SessionWriter>(out, info, writer_options);
    if (auto truth = rig_run.session_truth()) writer->write_truth(*truth);
  };
  bool sizes_known = true;
  for (const auto& cam : info.cameras) sizes_known &= cam.width > 0 && cam.height > 0;
  if (sizes_known) open_writer();  // otherwise the first set tells the image sizes

  fmt::print("tomorig run: rig '{}', {} cameras, {}{}\n", rig.name, rig.cameras.size(),
             acquisition.sets ? fmt::format("{} sets", *acquisition.sets)
                              : (opt.duration_s ? fmt::format("{:g} s", *opt.duration_s) : std::string("until Ctrl-C")),
             rig.simulation ? fmt::format(", case {} at {} ppp", rig.simulation->case_name, rig.simulation->ppp)
                            : std::string());
  std::fflush(stdout);

  zmq::context_t context(1);
  stream::SocketOptions pull;
  pull.endpoint = {kInprocEndpoint, /*bind=*/true, false};
  pull.timeout = 250ms;
  stream::FrameReceiver receiver(context, pull);
  stream::SocketOptions push = pull;
  push.endpoint.bind = false;
  stream::FrameSender sender(context, push);
  StatusReporter status("recording", context, opt.status);
  if (!status.endpoint().empty()) fmt::print(stderr, "run: status JSON on {}\n", status.endpoint());

  // Ctrl-C ends the run between sets: acquisition stops, the sets already taken are recorded,
  // and the file is closed complete and valid. A second Ctrl-C quits at once.
  const StopSignalGuard stop;
  const auto started = Clock::now();
  rig_run.start();
  StreamPump pump(rig_run, sender);

  LossTally losses(rig_run.camera_ids());
  StatusFigures figures;
  figures.total = acquisition.sets;
  std::string stopped_by;
  std::string disk_full;
  auto refresh = [&](bool final) {
    const RigProgress progress = rig_run.progress();
    const std::uint64_t in_stream = sender.stats().sets_sent - receiver.stats().sets_received;
    figures.queue_depth = progress.queued_sets + in_stream;
    figures.dropped_trigger_events = progress.dropped_trigger_events;
    status.update(figures, losses, final);
  };
  for (;;) {
    for (const auto& text : rig_run.take_notices()) {
      status.break_line();
      fmt::print(stderr, "run: {}\n", text);
    }
    if (stopped_by.empty() && stop.stop_requested()) {
      stopped_by = stop.signal_name();
      figures.state = "stopping";
      rig_run.request_stop();
    }
    std::optional<FrameSet> set;
    try {
      set = receiver.receive();
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;  // a signal: the loop head decides
      throw runtime_error(fmt::format("the in-process stream failed: {}", e.what()));
    }
    if (!set) {
      if (pump.done() && receiver.stats().sets_received >= sender.stats().sets_sent) break;
      refresh(false);
      continue;
    }
    losses.add(*set);
    if (!writer) {
      std::string why;
      auto cameras = cameras_from_set(*set, why);
      if (!cameras) continue;  // counted in the losses; a later complete set starts the session
      info.cameras = std::move(*cameras);
      open_writer();
    }
    try {
      writer->append(*set);
    } catch (const storage::DiskFullError& e) {
      disk_full = e.what();
      break;
    }
    if (auto truth = rig_run.take_truth(set->trigger_index)) writer->write_truth_set(figures.sets, *truth);
    ++figures.sets;
    figures.bytes += pixel_bytes(*set);
    refresh(false);
  }
  pump.abort();
  rig_run.request_stop();
  figures.state = disk_full.empty() && rig_run.failure().empty() ? "stopped" : "failed";
  refresh(true);
  pump.rethrow();

  if (!writer)
    throw runtime_error(fmt::format("no complete frame set arrived, so nothing was recorded{}",
                                    rig_run.failure().empty() ? "" : ": " + rig_run.failure()));
  writer->finish();
  std::error_code ec;
  const auto size = std::filesystem::file_size(out, ec);
  const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
  fmt::print("wrote {}: {} set{} x {} cameras, {} in {:.2f} s; {} lost frames, {} incomplete sets\n", out.string(),
             figures.sets, figures.sets == 1 ? "" : "s", info.cameras.size(), human_bytes(ec ? 0 : size), seconds,
             losses.frames_lost(), losses.incomplete_sets());
  fmt::print("next: tomorig inspect {}\n", out.string());
  if (!disk_full.empty())
    throw runtime_error(fmt::format("recording stopped: {}; {} is complete with {} sets", disk_full, out.string(),
                                    figures.sets));
  if (!rig_run.failure().empty())
    throw runtime_error(fmt::format("{}; {} is complete with {} sets", rig_run.failure(), out.string(), figures.sets));
  if (!stopped_by.empty())
    fmt::print(stderr, "stopped by {} after {} sets; the session is complete\n", stopped_by, figures.sets);
}

}  // namespace

void add_run_command(CLI::App& root) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = root.add_subcommand(
      "run", "Run the rig: trigger, acquire and record a session (default: the embedded simulated "
             "4-camera tpiv-thesis rig)");
  cmd->add_option("-c,--config", opt->config_path, "Rig file (TOML); default: the embedded rig")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--out", opt->out, "Session file to write; default: runs/session-<UTC time>.h5");
  auto* sets = cmd->add_option("--sets", opt->sets,
                               "Number of double-frame sets to record (default: simulation.sets of a simulated rig, "
                               "else until Ctrl-C)");
  cmd->add_option("--duration", opt->duration_s, "Record for this many seconds")->excludes(sets);
  cmd->add_option("--compression", opt->compression, "Frame compression: none | bitshuffle-lz4");
  cmd->add_flag("--overwrite", opt->overwrite, "Replace an existing output file");
  cmd->add_option("--pace", opt->pace,
                  "Simulated trigger: real-time (events at the rig's rate) | max (as fast as the recorder takes them)")
      ->capture_default_str();
  cmd->add_option("--on-camera-loss", opt->on_camera_loss,
                  "When a camera vanishes: stop (keep what was recorded) | continue (record its frames as missing)")
      ->capture_default_str();
  cmd->add_option("--status", opt->status, "Where the JSON status PUB socket binds; none: no socket")
      ->capture_default_str();
  cmd->add_option("--disk-reserve-mb", opt->disk_reserve_mb,
                  "Stop recording cleanly when the disk would have less than this many MB free")
      ->capture_default_str();
  cmd->add_option("--inject-fault", opt->faults,
                  "Testing: make a simulated camera fail, CAMERA:vanish-after=EVENTS (repeatable)");
  cmd->callback([opt] { run(*opt); });
}

}  // namespace tomorig::app
