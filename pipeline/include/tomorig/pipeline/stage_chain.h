#pragma once
// Running stages (stage.h): a StageRunner wraps one stage with the timing, counting, skipping
// and error capture every stage needs; a StageChain offers each FrameSet to all its stages.
//
// A stage that sees every set runs in the caller's thread, so a slow one slows the source
// (back-pressure, never loss); an error it throws reaches the caller. A stage that may skip
// runs on its own thread behind a short queue (Stage::max_waiting_sets(), one set by default):
// a set offered while the stage is busy waits there, and when the queue is full the oldest
// waiting set gives way to the newest (it counts as skipped). An error it
// throws stops that stage only; the report carries it, and the other stages go on.
#include <memory>
#include <string>
#include <vector>

#include "tomorig/pipeline/stage.h"

namespace tomorig::pipeline {

class StageRunner {
 public:
  StageRunner(std::string name, std::unique_ptr<Stage> stage);
  ~StageRunner();  // stops a worker without processing the sets still waiting
  StageRunner(const StageRunner&) = delete;
  StageRunner& operator=(const StageRunner&) = delete;

  void begin(const SessionDescription& recording);
  void offer(const FrameSet& set);
  // End of acquisition: a skipping stage first processes the sets still waiting for it, then
  // every stage's end() runs. Returns the report; call once.
  StageReport end();
  const std::string& name() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class StageChain {
 public:
  void add(std::string name, std::unique_ptr<Stage> stage);
  bool empty() const { return runners_.empty(); }
  void begin(const SessionDescription& recording);
  void push(const FrameSet& set);  // to every stage, in the order they were added
  std::vector<StageReport> end();  // every stage's report, in order

 private:
  std::vector<std::unique_ptr<StageRunner>> runners_;
};

}  // namespace tomorig::pipeline
