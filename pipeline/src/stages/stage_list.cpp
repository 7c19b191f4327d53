// pipeline's stages, one line each (the factory is defined in the stage's own file).
#include "tomorig/pipeline/stage_registry.h"

namespace tomorig::pipeline {

std::unique_ptr<Stage> make_frame_stats_stage();  // frame_stats_stage.cpp
std::unique_ptr<Stage> make_backend_stage();      // backend_stage.cpp
std::unique_ptr<Stage> make_quicklook_stage();    // quicklook/quicklook_stage.cpp

void add_pipeline_stages(StageRegistry& registry) {
  registry.add("frame-stats", "mean grey level and saturated fraction per camera of the newest set (may skip)",
               make_frame_stats_stage);
  registry.add("backend", "reconstruct and correlate each set into a results file (skip=true to stay current)",
               make_backend_stage);
  registry.add("quicklook", "statistics, dt check, preview volume and drift alarm of the newest sets; publish=ENDPOINT "
                            "(may skip)",
               make_quicklook_stage);
}

}  // namespace tomorig::pipeline
