#pragma once
// What a rig of simulated cameras sees at each trigger event: the particle cases through
// sim::SimulatedRig (simulated_rig.h), `spray-thesis` through the droplet-shadow renderer
// (spray.h, docs/spray.md). Chosen by the rig file's [simulation] case; shared by
// `tomorig run` / `acquire` (RigAcquisition) and `tomorig simulate --config`.
//
//   auto scene = rig::make_simulated_scene(rig_config);   // validates; throws bad_input
//   rig::SceneSet s = scene->render(k, scene->nominal_dt_ns());
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/frame_set.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

struct SceneSet {
  FrameSet frames;           // cameras x (A, B), in the rig's camera order and ids
  storage::TruthSet truth;   // particle / droplet centres at A and B, world mm
};

class SimulatedScene {
 public:
  virtual ~SimulatedScene() = default;
  // The session's cameras (ids, sizes, pixel format, pitch), in the rig's order.
  virtual const std::vector<storage::SessionCamera>& cameras() const = 0;
  // The session's /truth record (cameras, case, flow or spray parameters, seed).
  virtual storage::SessionTruth truth() const = 0;
  virtual std::size_t particles_per_set() const = 0;
  // The rig's pulse separation (trigger.dt_us), which render(k, nominal_dt_ns()) uses.
  virtual std::int64_t nominal_dt_ns() const = 0;
  // Event k fired with an actual pulse separation dt_ns (a live rig's jitter included): the
  // motion scales with dt_ns / nominal_dt_ns(). Frames are stamped at k / rate and + dt_ns.
  virtual SceneSet render(std::uint64_t index, std::int64_t dt_ns) const = 0;
};

// The scene of the rig file's [simulation] case; throws tomorig::Error (bad_input) naming the
// key when the rig cannot render it (no [simulation] table, a camera that is not simulated, a
// size or pixel format the case cannot give).
std::unique_ptr<SimulatedScene> make_simulated_scene(const config::RigConfig& rig);

// spray-thesis's scene (simulate_spray_scene.cpp); make_simulated_scene picks it by case.
std::unique_ptr<SimulatedScene> make_spray_scene(const config::RigConfig& rig);

}  // namespace tomorig::rig
