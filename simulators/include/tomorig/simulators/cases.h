#pragma once
// Built-in simulation cases, selectable by name. Each is defined once in
// ../shared/benchmarks/README.md and encoded here: cameras, seeded volume, flow, particle
// image size and the reconstruction grid it is evaluated on. docs/simulator.md says how to
// add one.
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "tomorig/core/pixel_format.h"
#include "tomorig/core/volume.h"
#include "tomorig/simulators/flow.h"
#include "tomorig/simulators/scene.h"

namespace tomorig::sim {

// A simulated pinhole camera yawed about the world y axis and looking at the origin
// (calibration::PinholeCamera::yawed). Mirrors config::CameraConfig without depending on it.
struct SimulatedCameraSpec {
  std::string id;
  double yaw_deg = 0.0;
  double focal_length_mm = 100.0;
  double pixel_pitch_um = 7.4;
  double distance_mm = 263.16;
  int width = 512;
  int height = 512;
  PixelFormat pixel_format = PixelFormat::Mono16;  // Mono12 or Mono16: the quantisation
};

struct CaseDefinition {
  std::string name;         // e.g. "tpiv-thesis"
  std::string description;  // one line, for listings
  std::vector<SimulatedCameraSpec> cameras;  // default cameras; a rig config may replace them
  Slab slab;                // seeded volume, world mm
  VoxelGrid grid;           // reconstruction grid the case is evaluated on
  double sigma_px = 0.75;   // particle image sigma
  std::function<std::unique_ptr<Flow>(const CaseDefinition&)> make_flow;
};

// All built-in cases, in a fixed order.
const std::vector<CaseDefinition>& cases();
// "tpiv-thesis, ...": the names, for messages.
std::string case_names();
// Throws tomorig::Error (bad_input) listing the available cases if `name` is unknown.
const CaseDefinition& find_case(std::string_view name);

// The individual cases (one .cpp each).
CaseDefinition tpiv_thesis_case();
CaseDefinition size_thesis_spray_case();

}  // namespace tomorig::sim
