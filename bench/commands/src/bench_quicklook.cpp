// tomorig bench quicklook: issue 16's throughput case. Sets of N cameras x side^2 Mono16 double
// frames (default 4 x 2048^2, 64 MiB a set) fed at the rig's rate (default 10 Hz) into a chain
// of the recorder (every set, into a live session file) and the quick-look stage (statistics,
// Δt check, preview volume, drift alarm, published on the preview stream), as `tomorig run
// --preview` feeds them. A few simulated sets (the tpiv-thesis scene through larger sensors)
// are rendered once and fed in turn, so rendering costs nothing during the measurement.
//
// What it reports: sets the recorder wrote against sets fed (loss), sets fed late (the recorder
// writes each set on the feeding thread, as on a rig; a set is late when the writes before it
// held the feed back by more than one period: on a live rig, frames waiting in the cameras'
// buffers, dropped once those are full) and the recorder's ms per set (--quicklook off
// measures the recorder alone, to tell the disk's share from the quick-look's),
// the quick-look's sets analysed and skipped, its milliseconds per camera frame, the preview
// volumes made and passed over with the latency of the last one, and the process's CPU share.
//
// --case spray-thesis feeds the spray rig instead (issue 20): 4 cameras of 2560 x 2160 Mono16
// (--reduced: 640 x 540), the spray-thesis case's own frames, so the quick-look runs its shadow
// mode; --recorder off leaves the disk out (88 MB a set at 25 Hz is more than most disks take),
// so the figure is the quick-look's own ms per set.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench_common.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/pipeline/stage_chain.h"
#include "tomorig/pipeline/stage_registry.h"
#include "tomorig/rig/rig_stages.h"
#include "tomorig/rig/simulate_session.h"
#include "tomorig/simulators/simulated_rig.h"
#include "tomorig/simulators/spray.h"

namespace tomorig::bench {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchQuickLookArgs {
  int cameras = 4;
  int side = 2048;
  double rate_hz = 10.0;
  int sets = 50;
  int distinct = 2;
  std::string quicklook = "on";
  std::string recorder = "on";
  std::string case_name = "tpiv-thesis";
  bool reduced = false;
  std::string preview = "on";
  std::string publish = "tcp://127.0.0.1:*";
  std::string folder = ".";
  std::string json_out;
};

// The tpiv-thesis rig with `side` x `side` sensors whose pixels are smaller by the same factor,
// so the cameras see the same field of view and the same particles.
std::string rig_toml(const BenchQuickLookArgs& a) {
  const double yaws[] = {-42.0, -14.0, 14.0, 42.0, -28.0, 28.0, 0.0, -56.0};
  std::string toml = "name = \"bench quicklook\"\n";
  for (int c = 0; c < a.cameras; ++c)
    toml += fmt::format(
        "[[cameras]]\nid = \"cam{0}\"\nbackend = \"simulated\"\npixel_format = \"Mono16\"\npixel_pitch_um = {1}\n"
        "yaw_deg = {2}\n[cameras.roi]\nwidth = {3}\nheight = {3}\n",
        c, 7.4 * 512.0 / a.side, yaws[c % 8], a.side);
  toml += fmt::format("[trigger]\nbackend = \"simulated\"\nrate_hz = {}\n", a.rate_hz);
  toml += "[simulation]\ncase = \"tpiv-thesis\"\nppp = 0.05\nnoise = true\n";
  return toml;
}

// The sets fed and the recording they claim to come from.
struct Feed {
  std::vector<FrameSet> sets;
  std::vector<storage::SessionCamera> cameras;
  storage::SessionTruth truth;
  std::string rig_toml;
};

Feed tpiv_feed(const BenchQuickLookArgs& args) {
  Feed feed;
  const config::RigConfig rig = config::parse_rig_config(rig_toml(args), "bench quicklook rig");
  const sim::SimulatedRig simulated(rig::simulation_options_from(rig));
  fmt::print(stderr, "bench quicklook: rendering {} sets of {} x {}^2 ...\n", args.distinct, args.cameras, args.side);
  for (int k = 0; k < args.distinct; ++k) feed.sets.push_back(simulated.render_set(static_cast<std::uint64_t>(k)).frames);
  feed.truth.case_name = "tpiv-thesis";
  for (const sim::SimulatedCamera& c : simulated.cameras()) {
    feed.cameras.push_back({c.spec.id, c.spec.width, c.spec.height, PixelFormat::Mono16, c.spec.pixel_pitch_um});
    feed.truth.cameras.push_back(rig::truth_camera_of(c));
  }
  feed.rig_toml = rig.source_text;
  return feed;
}

// The spray-thesis case's own sets (its 4 cameras; the quick-look's shadow mode needs no
// camera models, so the truth names the case only).
Feed spray_feed(const BenchQuickLookArgs& args) {
  Feed feed;
  sim::SprayOptions options;
  options.reduced = args.reduced;
  const sim::SprayCase c = sim::make_spray_thesis_case(options);
  fmt::print(stderr, "bench quicklook: rendering {} spray-thesis sets of {} x {} x {} ...\n", args.distinct,
             c.cameras.size(), c.cameras[0].width, c.cameras[0].height);
  for (int k = 0; k < args.distinct; ++k) feed.sets.push_back(sim::render_spray_set(c, static_cast<std::uint64_t>(k)).frames);
  feed.truth.case_name = c.name;
  for (const sim::SprayCamera& cam : c.cameras)
    feed.cameras.push_back({cam.id, cam.width, cam.height, PixelFormat::Mono16, cam.pixel_pitch_um});
  return feed;
}

void run(const BenchQuickLookArgs& args) {
  if (args.cameras < 1 || args.cameras > 8 || args.side < 64 || args.sets < 1 || args.distinct < 1 ||
      !(args.rate_hz > 0))
    throw bad_input("bench quicklook needs --cameras 1 to 8, --side >= 64, --sets >= 1, --distinct >= 1, --rate > 0");
  if (!fs::is_directory(args.folder)) throw bad_input(fmt::format("--folder '{}' is not a folder", args.folder));
  if (args.quicklook != "on" && args.quicklook != "off")
    throw bad_input(fmt::format("--quicklook {} is not one of on, off", args.quicklook));
  if (args.recorder != "on" && args.recorder != "off")
    throw bad_input(fmt::format("--recorder {} is not one of on, off", args.recorder));
  if (args.case_name != "tpiv-thesis" && args.case_name != "spray-thesis")
    throw bad_input(fmt::format("--case {} is not one of tpiv-thesis, spray-thesis", args.case_name));
  if (args.reduced && args.case_name != "spray-thesis")
    throw bad_input("--reduced is the spray-thesis case's: give --case spray-thesis, or --side for tpiv-thesis");
  const bool with_quicklook = args.quicklook == "on", with_recorder = args.recorder == "on";
  if (!with_quicklook && !with_recorder) throw bad_input("--quicklook off and --recorder off leave nothing to measure");
  const bool spray = args.case_name == "spray-thesis";
  const Feed feed = spray ? spray_feed(args) : tpiv_feed(args);
  const std::vector<FrameSet>& sets = feed.sets;
  const int cameras_per_set = static_cast<int>(feed.cameras.size());

  const fs::path out = fs::path(args.folder) / "tomorig-bench-quicklook.h5";
  std::vector<pipeline::StageSpec> specs;
  if (with_recorder) specs.push_back(pipeline::parse_stage_spec(fmt::format("recorder:out={},overwrite=true", out.string())));
  if (with_quicklook)
    specs.push_back(
        pipeline::parse_stage_spec(fmt::format("quicklook:preview={},publish={}", args.preview, args.publish)));
  pipeline::StageChain chain = pipeline::make_chain(rig::all_stages(), specs);
  chain.begin(pipeline::describe_recording("bench quicklook", feed.cameras, feed.rig_toml, feed.truth));

  const double period = 1.0 / args.rate_hz;
  fmt::print(stderr, "bench quicklook: feeding {} sets ({} MiB each) at {:g} Hz ...\n", args.sets,
             set_bytes(sets[0]) >> 20, args.rate_hz);
  const double cpu0 = process_cpu_seconds();
  const auto start = Clock::now();
  int late = 0;
  double worst_lateness = 0;
  for (int s = 0; s < args.sets; ++s) {
    const auto due = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s * period));
    std::this_thread::sleep_until(due);
    const double lateness = std::chrono::duration<double>(Clock::now() - due).count();
    worst_lateness = std::max(worst_lateness, lateness);
    if (lateness > period) ++late;
    FrameSet set = sets[static_cast<std::size_t>(s % args.distinct)];  // shares the pixels
    set.set_index = set.trigger_index = static_cast<std::uint64_t>(s);
    set.trigger_timestamp_ns = static_cast<std::int64_t>(s * period * 1e9);
    chain.push(set);
  }
  const double feed_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const std::vector<pipeline::StageReport> reports = chain.end();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu = process_cpu_seconds() - cpu0;
  std::error_code ec;
  if (with_recorder) fs::remove(out, ec);

  const pipeline::StageReport none;
  const pipeline::StageReport& recorder = with_recorder ? reports.at(0) : none;
  const pipeline::StageReport& quicklook = with_quicklook ? reports.at(with_recorder ? 1 : 0) : none;
  const auto written = with_recorder ? recorder.status.value("written", std::uint64_t{0}) : std::uint64_t{0};
  const double analysed = static_cast<double>(quicklook.processed);
  const double frames = analysed * cameras_per_set * 2;
  const double cores = std::max(1u, std::thread::hardware_concurrency());
  // The quick-look's CPU time (its threads' clocks): the figure that does not depend on what
  // else loads the machine. Busy seconds are wall time in process().
  const double ql_cpu = with_quicklook ? quicklook.status.value("cpu_seconds", 0.0) : 0.0;
  const double preview_cpu = with_quicklook ? quicklook.status.value("preview_cpu_seconds", 0.0) : 0.0;
  const nlohmann::json result = {
      {"bench", "quicklook"},
      {"machine", machine_json()},
      {"case", args.case_name},
      {"cameras", cameras_per_set},
      {"width", feed.cameras[0].width},
      {"height", feed.cameras[0].height},
      {"rate_hz", args.rate_hz},
      {"set_bytes", set_bytes(sets[0])},
      {"sets_fed", args.sets},
      {"feed_seconds", feed_seconds},
      {"seconds", seconds},
      {"recorder",
       !with_recorder ? nlohmann::json(nullptr) : nlohmann::json{{"written", written},
        {"lost", static_cast<std::uint64_t>(args.sets) - written},
        {"late_sets", late},
        {"worst_lateness_s", worst_lateness},
        {"busy_seconds", recorder.busy_seconds},
        {"ms_per_set", json_number(recorder.busy_seconds / std::max(1, args.sets) * 1e3)},
        {"error", recorder.error}}},
      {"quicklook",
       with_quicklook
           ? nlohmann::json{{"analysed", quicklook.processed},
                            {"skipped", quicklook.skipped},
                            {"busy_seconds", quicklook.busy_seconds},
                            {"ms_per_set", analysed > 0 ? json_number(quicklook.busy_seconds / analysed * 1e3) : nullptr},
                            {"cpu_ms_per_set", analysed > 0 ? json_number(ql_cpu / analysed * 1e3) : nullptr},
                            {"period_ms", 1e3 / args.rate_hz},
                            {"ms_per_camera_frame",
                             frames > 0 ? json_number(quicklook.busy_seconds / frames * 1e3) : nullptr},
                            {"cpu_ms_per_camera_frame", frames > 0 ? json_number(ql_cpu / frames * 1e3) : nullptr},
                            {"cpu_share", ql_cpu / seconds / cores},
                            {"preview_cpu_share", preview_cpu / seconds / cores},
                            {"status", quicklook.status},
                            {"error", quicklook.error}}
           : nlohmann::json(nullptr)},
      {"cpu_seconds", cpu},
      {"cpu_share", cpu / seconds / cores},
  };
  if (with_recorder)
    fmt::print(stderr, "bench quicklook: recorder wrote {} of {} sets ({} late, {:.0f} ms per set)", written, args.sets,
               late, recorder.busy_seconds / std::max(1, args.sets) * 1e3);
  else
    fmt::print(stderr, "bench quicklook: {} sets fed, no recorder ({} late)", args.sets, late);
  if (with_quicklook)
    fmt::print(stderr,
               "; quick-look analysed {} ({} skipped), {:.1f} ms per set of {} x 2 frames against the {:.0f} ms period "
               "({:.1f} ms CPU; {:.1f} ms per camera frame; statistics {:.0f} %, preview {:.0f} % of the CPU)",
               quicklook.processed, quicklook.skipped, analysed > 0 ? quicklook.busy_seconds / analysed * 1e3 : 0.0,
               cameras_per_set, 1e3 / args.rate_hz, analysed > 0 ? ql_cpu / analysed * 1e3 : 0.0,
               frames > 0 ? quicklook.busy_seconds / frames * 1e3 : 0.0, 100.0 * ql_cpu / seconds / cores,
               100.0 * preview_cpu / seconds / cores);
  fmt::print(stderr, "; CPU share {:.0f} %\n", 100.0 * result["cpu_share"].get<double>());
  write_json(result, args.json_out);
}

}  // namespace

void add_bench_quicklook_command(CLI::App& bench) {
  auto args = std::make_shared<BenchQuickLookArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "quicklook", "Recorder plus quick-look at the rig's rate: loss, late sets, ms per camera frame, CPU share");
  cmd->add_option("--cameras", args->cameras, "Cameras per set")->capture_default_str();
  cmd->add_option("--side", args->side, "Frame width and height, pixels (Mono16)")->capture_default_str();
  cmd->add_option("--rate", args->rate_hz, "Sets per second fed")->capture_default_str();
  cmd->add_option("--sets", args->sets, "Sets fed (each is written: sets x 64 MiB at the defaults)")
      ->capture_default_str();
  cmd->add_option("--distinct", args->distinct, "Different simulated sets rendered and fed in turn")
      ->capture_default_str();
  cmd->add_option("--quicklook", args->quicklook, "on, or off: the recorder alone (its own baseline)")
      ->capture_default_str();
  cmd->add_option("--recorder", args->recorder, "on, or off: the quick-look alone (no disk)")->capture_default_str();
  cmd->add_option("--case", args->case_name,
                  "tpiv-thesis (--cameras x --side^2 sensors) or spray-thesis (the spray rig's 4 x 2560 x 2160; "
                  "the quick-look's shadow mode)")
      ->capture_default_str();
  cmd->add_flag("--reduced", args->reduced, "spray-thesis at 640 x 540 (the example rig's size)");
  cmd->add_option("--preview", args->preview, "Preview volume: on, off, mlos or ment")->capture_default_str();
  cmd->add_option("--publish", args->publish, "Where the quick-look publishes (none: nowhere)")->capture_default_str();
  cmd->add_option("--folder", args->folder, "Folder for the recorded session (removed after)")->capture_default_str();
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json); --json alone, '-' or none: stdout")
      ->expected(0, 1);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
