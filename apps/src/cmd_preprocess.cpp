// tomorig preprocess: a session -> a preprocessed session (pipeline/preprocessed_session.h);
// this file parses the options and prints the report.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/console.h"
#include "tomorig/pipeline/preprocessed_session.h"

namespace tomorig::app {
namespace {

struct PreprocessArgs {
  std::string session;
  std::string chain;
  std::string out;
  std::string sets;
  bool overwrite = false;
  JsonOutput json;
};

void run(const PreprocessArgs& args) {
  cli::require_session(args.session, "preprocess");
  StatusLine status;
  const auto progress = [&](std::size_t pass, std::size_t passes, std::uint64_t done, std::uint64_t sets) {
    if (done == sets) status.finish(fmt::format("preprocess: pass {}/{}, set {}/{}", pass + 1, passes, done, sets));
    else if (status.due()) status.update(fmt::format("preprocess: pass {}/{}, set {}/{}", pass + 1, passes, done, sets));
  };
  const pipeline::PreprocessedSessionReport r = pipeline::write_preprocessed_session(
      {.session = args.session, .chain = args.chain, .out = args.out, .sets = args.sets, .overwrite = args.overwrite},
      progress);
  if (!args.json.to_stdout())
    fmt::print("wrote {} sets of {} cameras to {} ({} steps)\n", r.sets, r.cameras, args.out, r.steps);
  nlohmann::json j = json_summary("preprocess");
  j[json_key::kOut] = args.out;
  j[json_key::kSets] = r.sets;
  j[json_key::kCameras] = r.cameras;
  j["first_set"] = r.first_set;
  j["steps"] = r.steps;
  j["passes"] = r.passes;
  emit_json(args.json, j);
}

}  // namespace

void add_preprocess_command(CLI::App& root) {
  auto args = std::make_shared<PreprocessArgs>();
  CLI::App* cmd = root.add_subcommand(
      "preprocess", "Apply an image preprocessing chain (TOML) to a session and write a preprocessed session");
  cli::add_session_argument(*cmd, args->session, "Session file to read (.h5)");
  cmd->add_option("--chain", args->chain, "Preprocessing chain ([[preprocess.steps]] TOML, docs/preprocessing.md) or a preset: shadow-a, shadow-b "
                  "(thesis Sect. 7.4)")
      ->required();
  cmd->add_option("-o,--out", args->out, "Preprocessed session to write (.h5)")->required();
  cmd->add_option("--sets", args->sets, "Sets: N (the first N), A:B (A to B-1) or consecutive A-B; default all");
  cmd->add_flag("--overwrite", args->overwrite, "Replace an existing output file");
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
