#pragma once
// JSON forms of library reports, for --json output and for the report stored with a volume.
#include <nlohmann/json.hpp>

#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::pipeline {

nlohmann::json to_json(const recon::ReconstructionReport& report);

}  // namespace tomorig::pipeline
