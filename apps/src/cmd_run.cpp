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
#include "tomorig/rig/record_layout.h"
#include "tomorig/rig/rig_acquisition.h"
#include "tomorig/rig/rig_run_options.h"
#include "tomorig/rig/rig_session_info.h"
#include "tomorig/rig/rig_status.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::app {

using rig::complete_announced_cameras;
using rig::rig_session_info;
using rig::LossTally;
using rig::RigAcquisition;
using rig::RigAcquisitionOptions;
using rig::RigProgress;
using rig::RigRunChoices;
using rig::StatusFigures;
using rig::StatusReporter;
using rig::StopSignalGuard;
using rig::add_rig_run_options;
using rig::load_rig;
using rig::rig_acquisition_options;
using rig::run_length_text;
using rig::pixel_bytes;

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr const char* kInprocEndpoint = "inproc://tomorig-run";

struct RunOptions {
  RigRunChoices rig;
  std::string out;
  std::string compression = "none";
  bool overwrite = false;
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
  config::RigConfig rig = load_rig(opt.rig);
  const auto compression = storage::parse_compression(opt.compression);
  if (!compression)
    throw bad_input(fmt::format("--compression {} is not supported (none, bitshuffle-lz4)", opt.compression));
  if (!(opt.disk_reserve_mb >= 0.0))
    throw bad_input(fmt::format("--disk-reserve-mb {:g} is invalid: it must be >= 0", opt.disk_reserve_mb));

  RigAcquisitionOptions acquisition = rig_acquisition_options(rig, opt.rig);
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
  // The status socket too: an --status it refuses must not leave a .partial file behind.
  zmq::context_t context(1);
  StatusReporter status("recording", context, opt.rig.status);

  storage::SessionInfo info = rig_session_info(rig, rig_run);
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
             run_length_text(acquisition),
             rig.simulation ? fmt::format(", case {} at {} ppp", rig.simulation->case_name, rig.simulation->ppp)
                            : std::string());
  std::fflush(stdout);

  stream::SocketOptions pull;
  pull.endpoint = {kInprocEndpoint, /*bind=*/true, false};
  pull.timeout = 250ms;
  stream::FrameReceiver receiver(context, pull);
  stream::SocketOptions push = pull;
  push.endpoint.bind = false;
  stream::FrameSender sender(context, push);
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
  const std::filesystem::path out_folder = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
  auto refresh = [&](bool final) {
    const RigProgress progress = rig_run.progress();
    // Received first: a set sent after that read cannot make the difference negative.
    const std::uint64_t received = receiver.stats().sets_received;
    figures.queue_depth = progress.queued_sets + sets_in_flight(sender.stats().sets_sent, received);
    take_progress(figures, progress);
    std::error_code ec;
    const auto space = std::filesystem::space(out_folder, ec);
    if (!ec) figures.disk_free_bytes = space.available;
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
      auto cameras = complete_announced_cameras(info.cameras, *set, why);
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
  // Every set flagged is a run that did not work, whatever was written (a wrong frame_mode,
  // cameras not answering the trigger): it must not look like success. Free-running cameras
  // make no set complete by design and are warned about on every status line instead.
  bool free_running = false;
  for (const auto& cam : rig.cameras) free_running |= cam.frame_mode == config::FrameMode::free_run;
  if (figures.sets > 0 && losses.incomplete_sets() == figures.sets && !free_running && stopped_by.empty())
    throw runtime_error(fmt::format("none of the {} sets is complete ({} lost frames); {} keeps them, flagged. Check "
                                    "the cameras' frame_mode and the messages above",
                                    figures.sets, losses.frames_lost(), out.string()));
  if (!stopped_by.empty())
    fmt::print(stderr, "stopped by {} after {} sets; the session is complete\n", stopped_by, figures.sets);
}

}  // namespace

void add_run_command(CLI::App& root) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = root.add_subcommand(
      "run", "Run the rig: trigger, acquire and record a session (default: the embedded simulated "
             "4-camera tpiv-thesis rig)");
  add_rig_run_options(*cmd, opt->rig, "Record");
  cmd->add_option("-o,--out", opt->out, "Session file to write; default: runs/session-<UTC time>.h5");
  cmd->add_option("--compression", opt->compression, "Frame compression: none | bitshuffle-lz4");
  cmd->add_flag("--overwrite", opt->overwrite, "Replace an existing output file");
  cmd->add_option("--disk-reserve-mb", opt->disk_reserve_mb,
                  "Stop recording cleanly when the disk would have less than this many MB free")
      ->capture_default_str();
  cmd->callback([opt] { run(*opt); });
}

}  // namespace tomorig::app
