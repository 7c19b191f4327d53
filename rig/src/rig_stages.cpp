// rig's stages, one line each (the factory is defined in the stage's own file).
#include "tomorig/rig/rig_stages.h"

namespace tomorig::rig {

std::unique_ptr<pipeline::Stage> make_recorder_stage();  // recorder_stage.cpp

void add_rig_stages(pipeline::StageRegistry& registry) {
  registry.add("recorder", "write every set to a live session file (never skips)", make_recorder_stage);
}

const pipeline::StageRegistry& all_stages() {
  static const pipeline::StageRegistry registry = [] {
    pipeline::StageRegistry r;
    pipeline::add_pipeline_stages(r);
    add_rig_stages(r);
    return r;
  }();
  return registry;
}

}  // namespace tomorig::rig
