// tomorig stages: the stages a chain can hold (pipeline::StageRegistry, rig::all_stages()), and
// a chain run over a recorded session, set by set as a live rig would feed it. Skipping stages
// see every set here too unless they fall behind the reading of the file.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/set_selection.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/stage_registry.h"
#include "tomorig/rig/replay_schedule.h"
#include "tomorig/rig/rig_stages.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {
namespace {

struct StagesArgs {
  std::string session;
  std::vector<std::string> stages;
  std::string sets;  // the one set syntax; stages feeds a run of consecutive sets
  JsonOutput json;
};

void run(const StagesArgs& args) {
  const pipeline::StageRegistry& registry = rig::all_stages();
  if (args.session.empty()) {
    for (const auto& [type, summary] : registry.list()) fmt::print("{:<12} {}\n", type, summary);
    return;
  }
  if (args.stages.empty()) throw bad_input("give at least one --stage TYPE[:key=value,...] (tomorig stages lists them)");
  std::vector<pipeline::StageSpec> specs;
  for (const std::string& text : args.stages) specs.push_back(pipeline::parse_stage_spec(text));
  pipeline::StageChain chain = pipeline::make_chain(registry, specs);  // bad settings fail here

  const storage::SessionReader session(args.session);
  const auto [first, end] =
      (args.sets.empty() ? SetSelection() : SetSelection::parse(args.sets)).range(session.set_count());
  const rig::SetRange range{first, end};
  const rig::StopSignalGuard stop;
  chain.begin(pipeline::describe_session(session));
  for (std::uint64_t s = range.first; s < range.last && !stop.stop_requested(); ++s) chain.push(session.read_set(s));
  const std::vector<pipeline::StageReport> reports = chain.end();
  nlohmann::json summary = json_summary("stages");
  summary["stages"] = nlohmann::json::array();
  for (const auto& r : reports) summary["stages"].push_back(r.to_json());
  emit_json(args.json, summary);
  if (!args.json.to_stdout()) {
    for (const auto& r : reports) fmt::print("{}\n", r.brief());
  }
  if (stop.stop_requested()) throw runtime_error(fmt::format("stopped by {}", stop.signal_name()));
}

}  // namespace

void add_stages_command(CLI::App& root) {
  auto args = std::make_shared<StagesArgs>();
  CLI::App* cmd = root.add_subcommand(
      "stages", "List the pipeline stages, or run a chain of them over a recorded session (as a live rig would)");
  cli::add_session_argument(*cmd, args->session, "Session file (.h5) to feed through the stages; none: list the stages");
  cmd->add_option("--stage", args->stages, "TYPE or TYPE:key=value,key=value (repeatable; docs/architecture.md)");
  cmd->add_option("--sets", args->sets, "Sets: N (the first N), A:B (A to B-1) or consecutive A-B (default: all)");
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
