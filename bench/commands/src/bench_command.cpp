// tomorig bench <what>: figures for docs/performance.md and docs/accuracy.md, as JSON.
// Each benchmark lives in its own bench_<what>.cpp and registers itself here.
#include <CLI/CLI.hpp>

#include "tomorig/bench/bench_command.h"

namespace tomorig::bench {

void add_bench_stream_command(CLI::App& bench);  // bench_stream.cpp
void add_bench_record_command(CLI::App& bench);  // bench_record.cpp
void add_bench_recon_command(CLI::App& bench);   // bench_recon.cpp
void add_bench_piv3d_command(CLI::App& bench);   // bench_piv3d.cpp
void add_bench_recon_race_command(CLI::App& bench);  // bench_recon_race.cpp
void add_bench_calib_command(CLI::App& bench);   // bench_calib.cpp
void add_bench_quicklook_command(CLI::App& bench);  // bench_quicklook.cpp
void add_bench_spray_command(CLI::App& bench);  // bench_spray.cpp

void add_bench_command(CLI::App& root) {
  CLI::App* bench = root.add_subcommand("bench", "Measure speed and accuracy on simulated cases; print JSON");
  bench->require_subcommand(1);
  add_bench_stream_command(*bench);
  add_bench_record_command(*bench);
  add_bench_recon_command(*bench);
  add_bench_piv3d_command(*bench);
  add_bench_recon_race_command(*bench);
  add_bench_calib_command(*bench);
  add_bench_quicklook_command(*bench);
  add_bench_spray_command(*bench);
}

}  // namespace tomorig::bench
