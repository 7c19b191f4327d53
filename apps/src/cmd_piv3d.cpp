// tomorig piv3d: correlate two given volumes into a results file with one set
// (pipeline::correlate_volume_pair); this file parses the options and prints the report.
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/pipeline/correlation_args.h"
#include "tomorig/pipeline/volume_pair.h"

namespace tomorig::app {

using pipeline::add_correlation_flags;
using pipeline::to_json;

namespace {

struct Piv3dArgs {
  pipeline::VolumePairOptions options;
  JsonOutput json;
};

void run(const Piv3dArgs& args) {
  const pipeline::VolumePairReport report =
      pipeline::correlate_volume_pair(args.options, [](const std::string& message) { spdlog::info("{}", message); });
  const piv::CorrelationReport& c = report.correlation;
  nlohmann::json summary = json_summary("piv3d");
  summary.update(nlohmann::json{{"out", report.out},
                                {"xdmf", report.xdmf},
                                {"nodes", {report.nodes[0], report.nodes[1], report.nodes[2]}},
                                {"correlation", to_json(c)}});
  emit_json(args.json, summary);
  if (!args.json.to_stdout())
    fmt::print("wrote {} and {}: {} vectors, {:.1f} % valid, {} replaced, {} invalid, {:.1f} s\n", report.out,
               report.xdmf, c.valid + c.replaced + c.invalid, 100.0 * c.valid_fraction(), c.replaced, c.invalid,
               c.seconds_total);
}

}  // namespace

void add_piv3d_command(CLI::App& root) {
  auto args = std::make_shared<Piv3dArgs>();
  pipeline::VolumePairOptions& o = args->options;
  CLI::App* cmd = root.add_subcommand("piv3d", "Correlate two volumes (e.g. both exposures of a volume file) into a "
                                               "results file");
  cmd->add_option("--volumes", o.volumes, "Volume file (.h5, from tomorig reconstruct)")->required();
  cmd->add_option("--volume-b", o.volume_b, "Second volume file holding volume b (default: --volumes)");
  cmd->add_option("--a", o.name_a, "Name of the first volume")->capture_default_str();
  cmd->add_option("--b", o.name_b, "Name of the second volume")->capture_default_str();
  cmd->add_option("-o,--out", o.out, "Results file to write (.h5)")->required();
  cmd->add_flag("--overwrite", o.overwrite, "Replace the results file if it exists");
  cli::add_dt_option(*cmd, o.dt_ns, "Pulse separation (default: the one recorded in the volume file)");
  add_correlation_flags(*cmd, o.correlation);
  cmd->add_option("--threads", o.threads, "OpenMP threads (0: all cores)")->capture_default_str();
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
