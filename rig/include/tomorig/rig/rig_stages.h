#pragma once
// Every stage a rig or a replay can run: pipeline's (frame-stats, backend) and rig's own
// (recorder), by name. `tomorig run --stage` and `tomorig stages` build their chains from it.
#include "tomorig/pipeline/stage_registry.h"

namespace tomorig::rig {

// rig's stages, one line each: the recorder.
void add_rig_stages(pipeline::StageRegistry& registry);

// pipeline's stages and rig's.
const pipeline::StageRegistry& all_stages();

}  // namespace tomorig::rig
