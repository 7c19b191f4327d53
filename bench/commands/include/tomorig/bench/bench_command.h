#pragma once
// `tomorig bench ...`: speed and accuracy figures for docs/performance.md and docs/accuracy.md,
// printed as JSON. The benchmark commands live in bench/commands/ (not apps/), one
// bench_<what>.cpp each; the tomorig executable registers them through this one call.
namespace CLI {
class App;
}

namespace tomorig::bench {

void add_bench_command(CLI::App& root);

}  // namespace tomorig::bench
