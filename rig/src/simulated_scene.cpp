// The particle cases' scene: sim::SimulatedRig behind the SimulatedScene interface.
#include "tomorig/rig/simulated_scene.h"

#include <utility>

#include "tomorig/rig/simulate_session.h"
#include "tomorig/simulators/simulated_rig.h"

namespace tomorig::rig {
namespace {

class ParticleScene final : public SimulatedScene {
 public:
  explicit ParticleScene(const config::RigConfig& rig) : simulator_(simulation_options_from(rig)) {
    for (const sim::SimulatedCamera& cam : simulator_.cameras())
      cameras_.push_back({cam.spec.id, cam.spec.width, cam.spec.height, cam.spec.pixel_format, cam.spec.pixel_pitch_um});
  }
  const std::vector<storage::SessionCamera>& cameras() const override { return cameras_; }
  storage::SessionTruth truth() const override {
    storage::SessionTruth truth;
    truth.case_name = simulator_.case_definition().name;
    truth.flow_name = simulator_.flow().name();
    truth.flow_parameters = simulator_.flow().parameters_json();
    truth.seed = simulator_.options().seed;
    truth.ppp = simulator_.options().ppp;
    for (const sim::SimulatedCamera& cam : simulator_.cameras()) truth.cameras.push_back(truth_camera_of(cam));
    return truth;
  }
  std::size_t particles_per_set() const override { return simulator_.particles_per_set(); }
  std::int64_t nominal_dt_ns() const override { return simulator_.options().dt_ns; }
  SceneSet render(std::uint64_t index, std::int64_t dt_ns) const override {
    sim::SimulatedSet set = simulator_.render_set(index, dt_ns);
    return {std::move(set.frames), {std::move(set.particles_a), std::move(set.particles_b)}};
  }

 private:
  sim::SimulatedRig simulator_;
  std::vector<storage::SessionCamera> cameras_;
};

}  // namespace

std::unique_ptr<SimulatedScene> make_simulated_scene(const config::RigConfig& rig) {
  if (rig.simulation && rig.simulation->case_name == "spray-thesis") return make_spray_scene(rig);
  return std::make_unique<ParticleScene>(rig);
}

}  // namespace tomorig::rig
