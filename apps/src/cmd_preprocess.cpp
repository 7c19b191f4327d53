// tomorig preprocess: a session -> a preprocessed session (same layout, Mono16 frames), so a
// preprocessing chain can be checked by eye (tomorig inspect --png) before a long run.
//
// Steps that need a sequence statistic (subtract_minimum, normalize by average_image) get it
// from an earlier streaming pass over the selected sets, one pass per such step, per camera
// and exposure; the last pass writes the output. Float results are rounded and clipped to
// [0, 65535] (docs/preprocessing.md).
#include <array>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "commands.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/set_selection.h"
#include "json_summary.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "tomorig/core/console.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/preprocess/chain_spec.h"
#include "tomorig/processing/preprocess/image_chain.h"
#include "tomorig/processing/preprocess/sequence_image.h"
#include "tomorig/storage/output_path.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {

using pipeline::reference_image;

namespace {

namespace fs = std::filesystem;
using preprocess::ImageChain;

struct PreprocessArgs {
  std::string session;
  std::string chain;
  std::string out;
  std::string sets;
  bool overwrite = false;
  JsonOutput json;
};

struct SetRange {
  std::uint64_t first = 0;
  std::uint64_t end = 0;  // one past the last
};

// The one set syntax (core/set_selection.h); preprocess writes a run of consecutive sets.
SetRange parse_sets(const std::string& text, std::uint64_t count) {
  const SetSelection selection = text.empty() ? SetSelection() : SetSelection::parse(text);
  const auto [first, end] = selection.range(count);
  return {first, end};
}

// A relative reference path in the chain file is relative to the chain file's folder.
fs::path resolve(const std::string& file, const fs::path& chain_path) {
  const fs::path p(file);
  return p.is_absolute() ? p : chain_path.parent_path() / p;
}

void run(const PreprocessArgs& args) {
  cli::require_session(args.session, "preprocess");
  // Before the sequence passes, which can take minutes: an existing output is refused now.
  storage::check_output_path(args.out, args.overwrite, "session");
  const preprocess::ChainSpec spec = preprocess::read_chain(args.chain);
  const storage::SessionReader session(args.session);
  const SetRange range = parse_sets(args.sets, session.set_count());
  const auto& cameras = session.info().cameras;

  std::vector<ImageChain> chains;
  for (const auto& camera : cameras) {
    chains.emplace_back(spec);
    for (std::size_t i = 0; i < spec.steps.size(); ++i)
      if (preprocess::needs_reference_image(spec.steps[i]))
        chains.back().set_reference_image(i, reference_image(resolve(spec.steps[i].file, args.chain), camera.id, i));
  }

  std::vector<std::size_t> sequence_steps;
  for (std::size_t i = 0; i < spec.steps.size(); ++i)
    if (preprocess::needs_sequence_image(spec.steps[i])) sequence_steps.push_back(i);
  const std::size_t passes = sequence_steps.size() + 1;
  const std::uint64_t set_total = range.end - range.first;
  StatusLine status;
  const auto progress = [&](std::size_t pass, std::uint64_t done) {
    if (done == set_total) status.finish(fmt::format("preprocess: pass {}/{}, set {}/{}", pass + 1, passes, done, set_total));
    else if (status.due()) status.update(fmt::format("preprocess: pass {}/{}, set {}/{}", pass + 1, passes, done, set_total));
  };

  // Streaming passes: the chain up to each sequence step, folded into a minimum or an average.
  for (std::size_t p = 0; p < sequence_steps.size(); ++p) {
    const std::size_t step = sequence_steps[p];
    const bool minimum = spec.steps[step].kind == preprocess::StepKind::subtract_minimum;
    std::vector<std::array<preprocess::MinimumImage, 2>> minima(cameras.size());
    std::vector<std::array<preprocess::MeanImage, 2>> means(cameras.size());
    for (std::uint64_t s = range.first; s < range.end; ++s) {
      const FrameSet set = session.read_set(s);
      for (std::size_t c = 0; c < set.cameras.size() && c < chains.size(); ++c)
        for (const Exposure e : {Exposure::A, Exposure::B}) {
          const Frame& frame = set.cameras[c][e];
          if (!frame.present()) continue;
          const Image& partial = chains[c].run(frame.image, e, step);
          if (minimum) minima[c][static_cast<int>(e)].add(partial);
          else means[c][static_cast<int>(e)].add(partial);
        }
      progress(p, s - range.first + 1);
    }
    for (std::size_t c = 0; c < chains.size(); ++c)
      for (const Exposure e : {Exposure::A, Exposure::B}) {
        const int k = static_cast<int>(e);
        if ((minimum ? minima[c][k].count() : means[c][k].count()) == 0)
          throw bad_input(fmt::format("camera '{}' has no frame {} in the selected sets, so step {} ({}) has no "
                                      "sequence image; select more sets", cameras[c].id, k == 0 ? "A" : "B", step,
                                      to_string(spec.steps[step].kind)));
        chains[c].set_sequence_image(step, e, minimum ? minima[c][k].result() : means[c][k].result());
      }
  }

  storage::SessionInfo info = session.info();
  info.software_version.clear();
  info.created_utc.clear();
  for (auto& camera : info.cameras) camera.pixel_format = PixelFormat::Mono16;
  storage::SessionWriterOptions options;
  options.compression = session.info().compression;
  options.overwrite = args.overwrite;
  storage::SessionWriter writer(args.out, info, options);
  if (session.has_truth()) writer.write_truth(session.truth());

  for (std::uint64_t s = range.first; s < range.end; ++s) {
    FrameSet set = session.read_set(s);
    for (std::size_t c = 0; c < set.cameras.size() && c < chains.size(); ++c)
      for (const Exposure e : {Exposure::A, Exposure::B}) {
        Frame& frame = set.cameras[c][e];
        if (!frame.present()) continue;
        Image out;  // a fresh image: the FrameSet keeps it until append() has written it
        preprocess::to_uint16(chains[c].run(frame.image, e), out);
        frame.image = out;
      }
    writer.append(set);
    if (session.has_truth_set(s)) writer.write_truth_set(s - range.first, session.truth_set(s));
    progress(passes - 1, s - range.first + 1);
  }
  writer.finish();
  if (!args.json.to_stdout())
    fmt::print("wrote {} sets of {} cameras to {} ({} steps)\n", set_total, cameras.size(), args.out, spec.steps.size());
  nlohmann::json j = json_summary("preprocess");
  j[json_key::kOut] = args.out;
  j[json_key::kSets] = set_total;
  j[json_key::kCameras] = cameras.size();
  j["first_set"] = range.first;
  j["steps"] = spec.steps.size();
  j["passes"] = passes;
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
