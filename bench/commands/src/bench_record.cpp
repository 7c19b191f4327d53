// tomorig bench record: thesis-scale FrameSets through the live session recorder, with and
// without bitshuffle-LZ4, next to a raw sequential write of the same bytes to the same folder
// in the same run (issue 6, docs/performance.md). Both are timed up to fdatasync, so the page
// cache does not flatter either.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench_common.h"
#include "tomorig/core/console.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::bench {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchRecordArgs {
  int sets = 24;
  int cameras = 4;
  int side = 2048;
  std::string folder = ".";
  std::string json_out;
};

void sync_file(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw runtime_error(fmt::format("cannot reopen '{}' to sync it", path.string()));
  const int status = ::fdatasync(fd);
  ::close(fd);
  if (status != 0) throw runtime_error(fmt::format("fdatasync of '{}' failed (is the disk full?)", path.string()));
}

double raw_write_mb_per_s(const FrameSet& set, int sets, const fs::path& file) {
  const auto start = Clock::now();
  {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) throw bad_input(fmt::format("cannot write '{}': is the folder writable?", file.string()));
    for (int s = 0; s < sets; ++s)
      for (const auto& cam : set.cameras)
        for (const Frame* f : {&cam.a, &cam.b}) {
          const auto* p = reinterpret_cast<const char*>(f->image.data());
          std::size_t left = f->image.size_bytes();
          while (left > 0) {
            const ssize_t n = ::write(fd, p, left);
            if (n <= 0) {
              ::close(fd);
              throw runtime_error(fmt::format("writing '{}' failed (is the disk full?)", file.string()));
            }
            p += n;
            left -= static_cast<std::size_t>(n);
          }
        }
    ::fdatasync(fd);
    ::close(fd);
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  fs::remove(file);
  return static_cast<double>(set_bytes(set)) * sets / seconds / 1e6;
}

nlohmann::json record_run(const FrameSet& set, const BenchRecordArgs& args, storage::Compression compression,
                          const fs::path& file) {
  storage::SessionInfo info;
  for (const auto& cam : set.cameras) info.cameras.push_back({cam.camera_id, args.side, args.side, PixelFormat::Mono16, 6.5});
  storage::SessionWriterOptions options;
  options.compression = compression;
  options.live = true;  // as the recorder of a running rig writes
  options.overwrite = true;
  const double cpu0 = process_cpu_seconds();
  const auto start = Clock::now();
  {
    storage::SessionWriter writer(file, info, options);
    StatusLine status;  // a long run is not silent (issue 23); due() is one clock read per set
    for (int s = 0; s < args.sets; ++s) {
      FrameSet copy = set;  // shares the pixels
      copy.trigger_index = static_cast<std::uint64_t>(s);
      writer.append(copy);
      if (status.due())
        status.update(fmt::format("bench record: {} set {}/{}", storage::to_string(compression), s + 1, args.sets));
    }
    writer.finish();
    status.break_line();
  }
  sync_file(file);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu = process_cpu_seconds() - cpu0;
  const double bytes = static_cast<double>(set_bytes(set)) * args.sets;
  const auto file_bytes = fs::file_size(file);
  fs::remove(file);
  return {{"compression", std::string(storage::to_string(compression))},
          {"sets", args.sets},
          {"seconds", seconds},
          {"mb_per_s", bytes / seconds / 1e6},
          {"sets_per_s", args.sets / seconds},
          {"cpu_seconds", cpu},
          {"file_bytes", file_bytes},
          {"compression_ratio", bytes / static_cast<double>(file_bytes)}};
}

void run(const BenchRecordArgs& args) {
  if (args.sets < 1 || args.cameras < 1 || args.side < 16)
    throw bad_input("bench record needs --sets >= 1, --cameras >= 1 and --side >= 16");
  const fs::path folder = args.folder;
  if (!fs::is_directory(folder)) throw bad_input(fmt::format("--folder '{}' is not a folder", args.folder));
  const FrameSet set = synthetic_particle_set(args.cameras, args.side, 2);
  fmt::print(stderr, "bench record: {} sets of {} MiB into {}\n", args.sets, set_bytes(set) >> 20, folder.string());
  // The raw write runs before and after the recorder and the faster run counts, so a cold
  // first write (block allocation, a busy disk) does not flatter the recorder's ratio.
  const fs::path raw_file = folder / "tomorig-bench-raw.bin";
  const double raw_before = raw_write_mb_per_s(set, args.sets, raw_file);
  fmt::print(stderr, "  raw write       {:8.0f} MB/s\n", raw_before);
  nlohmann::json results = nlohmann::json::array();
  for (const auto compression : {storage::Compression::none, storage::Compression::bitshuffle_lz4}) {
    nlohmann::json r = record_run(set, args, compression, folder / "tomorig-bench-record.h5");
    fmt::print(stderr, "  {:15} {:8.0f} MB/s  (compression {:.2f}x)\n", r["compression"].get<std::string>(),
               r["mb_per_s"].get<double>(), r["compression_ratio"].get<double>());
    results.push_back(std::move(r));
  }
  const double raw_after = raw_write_mb_per_s(set, args.sets, raw_file);
  fmt::print(stderr, "  raw write       {:8.0f} MB/s\n", raw_after);
  const double raw = std::max(raw_before, raw_after);
  for (auto& r : results) r["ratio_to_raw_write"] = r["mb_per_s"].get<double>() / raw;
  write_json({{"bench", "record"},
              {"machine", machine_json()},
              {"folder", fs::absolute(folder).string()},
              {"set_bytes", set_bytes(set)},
              {"raw_write_mb_per_s", raw},
              {"raw_write_runs_mb_per_s", {raw_before, raw_after}},
              {"results", results}},
             args.json_out);
}

}  // namespace

void add_bench_record_command(CLI::App& bench) {
  auto args = std::make_shared<BenchRecordArgs>();
  CLI::App* cmd =
      bench.add_subcommand("record", "FrameSets through the live HDF5 recorder vs a raw write of the same bytes");
  cmd->add_option("--sets", args->sets, "Sets to record")->capture_default_str();
  cmd->add_option("--cameras", args->cameras, "Cameras per set")->capture_default_str();
  cmd->add_option("--side", args->side, "Frame width and height, pixels (Mono16)")->capture_default_str();
  cmd->add_option("--folder", args->folder, "Folder on the disk to measure (files are removed after)")
      ->capture_default_str();
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json); --json alone, '-' or none: stdout")
      ->expected(0, 1);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
