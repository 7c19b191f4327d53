#pragma once
// A stage of a FrameSet pipeline, in the spirit of odin-data's frame-processor plugins. A stage
// is configured from a table (a TOML table or `key=value` pairs), told what recording it is
// about to see (begin), fed FrameSets, live or replayed, one at a time (process), told that the
// acquisition ended (end), and reports (status). Its author writes only that; the StageRunner
// around it does the timing, the counting, the skipping and the error capture.
//
// A stage either sees every set (the recorder, the back-end on a replay: the source waits for
// it) or may skip sets to stay current (a quick-look: it gets the newest set whenever it is
// free, and the sets it never saw are counted as skipped). Adding one is one file plus one
// registration line (stage_registry.h; docs/architecture.md has a worked example).
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/pipeline/session_geometry.h"

namespace tomorig::pipeline {

// The settings of one stage. Each getter takes the value to use when the key is absent, which
// should be the stage's own Options default, so every parameter keeps one default. Errors name
// the stage and the key.
class StageTable {
 public:
  StageTable() = default;
  // `values`: a JSON object (a TOML table converts one to one). `stage` names it in messages.
  StageTable(nlohmann::json values, std::string stage);
  // "key=value,key=value"; a value that reads as a number or true/false is one, else a string.
  // Throws bad_input quoting the malformed part.
  static StageTable parse(const std::string& text, std::string stage);

  double number(const std::string& key, double absent) const;
  std::int64_t integer(const std::string& key, std::int64_t absent) const;
  bool flag(const std::string& key, bool absent) const;
  std::string text(const std::string& key, const std::string& absent) const;
  bool has(const std::string& key) const;
  const std::string& stage() const { return stage_; }

  // Throws bad_input naming a key that no getter asked for (a typo), with the keys that were.
  void check_all_used() const;

 private:
  const nlohmann::json* find(const std::string& key) const;
  nlohmann::json values_ = nlohmann::json::object();
  std::string stage_;
  mutable std::set<std::string> used_;
};

class Stage {
 public:
  virtual ~Stage() = default;
  // Reads the stage's settings; throws bad_input naming the key. Called once, before begin().
  virtual void configure(const StageTable& table) = 0;
  // The recording the sets will come from (cameras, rig config, truth). Called once.
  virtual void begin(const SessionDescription& recording) {}
  // One set. May throw tomorig::Error; the runner records it.
  virtual void process(const FrameSet& set) = 0;
  // The acquisition ended: flush and close (end-of-acquisition marker). Called once.
  virtual void end() {}
  // The stage's own figures for the report (a JSON object), e.g. what it wrote.
  virtual nlohmann::json status() const { return nlohmann::json::object(); }
  // True: the stage may skip sets to stay current; false: it sees every set.
  virtual bool may_skip() const { return false; }
  // A skipping stage: how many sets may wait for it before the oldest waiting one is skipped.
  // 1 keeps only the newest (a preview that must be current); a few let a stage that is fast
  // enough on average ride out a slow moment (a cold cache, a scheduler hiccup) without a skip.
  virtual std::size_t max_waiting_sets() const { return 1; }
};

// What a StageRunner reports about its stage.
struct StageReport {
  std::string name;                 // the stage's type in the registry
  std::uint64_t offered = 0;        // sets the source offered
  std::uint64_t processed = 0;      // sets process() finished
  std::uint64_t skipped = 0;        // sets a skipping stage never saw, to stay current
  double busy_seconds = 0.0;        // in process()
  std::string error;                // the error that stopped the stage; empty if none
  nlohmann::json status = nlohmann::json::object();  // Stage::status() at the end

  // "quicklook: 40 of 120 sets (80 skipped), 3.2 s busy"
  std::string brief() const;
  nlohmann::json to_json() const;
};

}  // namespace tomorig::pipeline
