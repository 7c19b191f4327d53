#include "tomorig/pipeline/report_json.h"

namespace tomorig::pipeline {

nlohmann::json to_json(const recon::ReconstructionReport& r) {
  nlohmann::json history = nlohmann::json::array();
  for (const recon::IterationStats& it : r.history)
    history.push_back({{"iteration", it.iteration},
                       {"residual", it.residual},
                       {"mean_update", it.mean_update},
                       {"seconds", it.seconds}});
  return {{"algorithm", r.algorithm},
          {"iterations", r.iterations},
          {"history", history},
          {"active_voxels", r.active_voxels},
          {"nonzero_voxels", r.nonzero_voxels},
          {"setup_seconds", r.setup_seconds},
          {"seconds", r.seconds},
          {"peak_rss_mb", r.peak_rss_mb},
          {"estimated_memory_mb", r.estimated_memory_mb},
          {"threads", r.threads}};
}

}  // namespace tomorig::pipeline
