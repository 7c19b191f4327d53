#include "spray_truth.h"

#include <cmath>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"
#include "tomorig/rig/simulate_spray.h"

namespace tomorig::bench {

sim::SprayCase spray_case_of(const storage::SessionTruth& truth) {
  if (truth.case_name != "spray-thesis")
    throw bad_input(fmt::format("the session's truth is of case '{}': droplet accuracy needs a spray-thesis session "
                                "('tomorig run --config docs/examples/spray-thesis-rig.toml' or 'tomorig simulate "
                                "--case spray-thesis')",
                                truth.case_name));
  const nlohmann::json p = nlohmann::json::parse(truth.flow_parameters, nullptr, false);
  if (p.is_discarded() || !p.is_object() || !p.contains("pattern"))
    throw bad_input("the session's spray truth holds no options (flow_parameters): it cannot be regenerated");
  try {
    sim::SprayOptions o;
    o.seed = truth.seed;
    o.pattern = rig::parse_spray_pattern(p.at("pattern").get<std::string>(), "the session's spray truth (pattern)");
    o.reduced = p.at("reduced").get<bool>();
    o.droplets = p.at("droplets_per_set").get<int>();
    o.d_median_um = p.at("d_median_um").get<double>();
    o.d_log_sigma = p.at("d_log_sigma").get<double>();
    o.d_min_um = p.at("d_range_um").at(0).get<double>();
    o.d_max_um = p.at("d_range_um").at(1).get<double>();
    o.dt_us = p.at("dt_us").get<double>();
    o.bright_fraction = p.at("bright_fraction").get<double>();
    o.vignetting = p.at("vignetting").get<double>();
    o.pulse_jitter = p.at("pulse_jitter").get<double>();
    o.pulse_b_energy = p.at("pulse_b_energy").get<double>();
    o.noise = p.at("noise").get<bool>();
    return sim::make_spray_thesis_case(o);
  } catch (const nlohmann::json::exception& e) {
    throw bad_input(fmt::format("the session's spray truth (flow_parameters) lacks an option: {}", e.what()));
  }
}

std::vector<TruthDroplet> spray_truth_droplets(const storage::SessionReader& session, const sim::SprayCase& c,
                                               std::uint64_t set_index) {
  if (!session.has_truth_set(set_index))
    throw bad_input(fmt::format("set {} has no truth (/truth/sets/{}): choose sets with truth (--sets)", set_index,
                                set_index));
  const storage::TruthSet t = session.truth_set(set_index);
  const std::vector<sim::Droplet> regenerated = sim::spray_droplets(c, session.set_record(set_index).trigger_index);
  if (regenerated.size() != t.particles_a.size() || t.particles_b.size() != t.particles_a.size())
    throw bad_input(fmt::format("set {}: the truth holds {} droplets but its case regenerates {}: the truth does not "
                                "belong to these options",
                                set_index, t.particles_a.size(), regenerated.size()));
  std::vector<TruthDroplet> out(t.particles_a.size());
  for (std::size_t n = 0; n < out.size(); ++n) {
    // The renderer keeps each droplet's mid-time position whatever the actual pulse separation.
    const Vec3d mid_truth = (t.particles_a[n] + t.particles_b[n]) * 0.5;
    const Vec3d mid_case = (regenerated[n].a + regenerated[n].b) * 0.5;
    if ((mid_truth - mid_case).norm() > 1e-6)
      throw bad_input(fmt::format("set {}: droplet {} of the truth is not where its case puts it: the truth does not "
                                  "belong to these options",
                                  set_index, n));
    out[n] = {t.particles_a[n], t.particles_b[n], regenerated[n].d_um};
  }
  return out;
}

}  // namespace tomorig::bench
