#pragma once
// `tomorig preprocess`: a session -> a preprocessed session (same layout, Mono16 frames), so a
// preprocessing chain can be checked by eye (tomorig inspect --png) before a long run. Steps
// that need a sequence statistic (subtract_minimum, normalize by average_image) get it from an
// earlier streaming pass over the selected sets (SessionPreprocessor); the last pass writes the
// output. Float results are rounded and clipped to [0, 65535] (docs/preprocessing.md).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace tomorig::pipeline {

struct PreprocessedSessionOptions {
  std::filesystem::path session;
  std::filesystem::path chain;  // chain TOML or a preset (shadow-a, shadow-b)
  std::filesystem::path out;    // the preprocessed session
  std::string sets;             // SetSelection text, a contiguous run; empty: every set
  bool overwrite = false;
};

struct PreprocessedSessionReport {
  std::uint64_t first_set = 0, sets = 0;
  std::size_t cameras = 0, steps = 0;
  std::size_t passes = 0;  // over the sets: one per sequence statistic, and the writing one
};

// After each set of each pass: pass (0-based) of `passes`, sets done of `sets`.
using PreprocessProgress =
    std::function<void(std::size_t pass, std::size_t passes, std::uint64_t done, std::uint64_t sets)>;

// The output is checked before any work (an existing one is refused, bad_input, without
// `overwrite`). Throws tomorig::Error (bad_input) naming what is wrong and the fix.
PreprocessedSessionReport write_preprocessed_session(const PreprocessedSessionOptions& options,
                                                     const PreprocessProgress& progress = {});

}  // namespace tomorig::pipeline
