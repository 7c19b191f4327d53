#pragma once
// The correlation flags shared by `process`, `piv3d` and `bench piv3d`, turned into
// piv::CorrelationOptions, and the JSON of options and reports stored in results files.
#include <string>

#include <nlohmann/json.hpp>

#include "tomorig/processing/correlation/correlate.h"

namespace CLI {
class App;
}

namespace tomorig::pipeline {

struct CorrelationArgs {
  std::string window = "32,32,32";  // final interrogation volume, voxels x,y,z
  double overlap = 0.75;
  int deformation_passes = 2;
  std::string weighting = "gaussian";
  double gaussian_sigma = 0.5;  // fraction of the window edge: wide, for reconstructed volumes (docs/correlation.md)
  std::string interpolation = "bspline";
  double min_peak = piv::CorrelationOptions{}.min_peak;                  // the library's default
  double max_displacement = piv::CorrelationOptions{}.max_displacement;  // the library's default
  int threads = 0;
};

// Adds --window, --overlap, --deformation-passes, --weighting, --gaussian-sigma, --interpolation, --min-peak,
// --max-displacement to `cmd` (threads come from the command's own --threads).
void add_correlation_flags(CLI::App& cmd, CorrelationArgs& args);

// The multigrid scheme of CorrelationOptions::multigrid with the given flags. Throws
// tomorig::Error (bad_input) quoting a malformed --window.
piv::CorrelationOptions correlation_options(const CorrelationArgs& args);
piv::WindowSize parse_window(const std::string& text);

nlohmann::json to_json(const piv::CorrelationOptions& options);
nlohmann::json to_json(const piv::CorrelationReport& report);

}  // namespace tomorig::pipeline
