#pragma once
// Stages by name. A library's stages are registered in one list function, one line each:
//
//   void add_pipeline_stages(StageRegistry& r) {           // pipeline/src/stages/stage_list.cpp
//     r.add("frame-stats", "brightness and saturation per camera (may skip)", make<FrameStatsStage>);
//     r.add("backend", "reconstruct and correlate into a results file", make<BackendStage>);
//   }
//
// (a list, not self-registering static objects: a static library drops object files nobody
// references, and their registrations with them). rig::add_rig_stages adds the recorder.
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tomorig/pipeline/stage.h"
#include "tomorig/pipeline/stage_chain.h"

namespace tomorig::pipeline {

using StageFactory = std::function<std::unique_ptr<Stage>()>;

template <typename StageType>
std::unique_ptr<Stage> make() {
  return std::make_unique<StageType>();
}

// A stage as the command line or a table names it: "type" or "type:key=value,key=value".
struct StageSpec {
  std::string type;
  StageTable table;
};
// Throws bad_input quoting `text` when it is malformed.
StageSpec parse_stage_spec(const std::string& text);

class StageRegistry {
 public:
  // Throws std::logic_error for a type added twice (a programming error).
  void add(std::string type, std::string summary, StageFactory factory);
  // A configured stage: configure() and then check_all_used() on `spec.table`. Throws
  // bad_input for an unknown type, listing the known ones, or a bad setting.
  std::unique_ptr<Stage> create(const StageSpec& spec) const;
  // (type, summary), in registration order.
  const std::vector<std::pair<std::string, std::string>>& list() const { return summaries_; }

 private:
  std::vector<std::pair<std::string, std::string>> summaries_;
  std::vector<StageFactory> factories_;
};

// pipeline's own stages: frame-stats, backend.
void add_pipeline_stages(StageRegistry& registry);

// A chain of configured stages, in the order given.
StageChain make_chain(const StageRegistry& registry, const std::vector<StageSpec>& specs);

}  // namespace tomorig::pipeline
