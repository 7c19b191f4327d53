#include <cstdint>

#include <fmt/format.h>

#include "decode.h"

namespace tomorig::config {

// The cases of ../shared/benchmarks/README.md, which the simulator selects by name.
const std::vector<std::string>& simulation_case_names() {
  static const std::vector<std::string> names{"tpiv-thesis", "size-thesis-spray", "spray-thesis", "calib-thesis"};
  return names;
}

namespace detail {

void decode_simulation(TableReader& root, std::optional<SimulationConfig>& simulation) {
  auto r = root.table("simulation");
  if (!r) return;
  SimulationConfig s;
  r->read("case", s.case_name, Need::optional, one_of<std::string>(simulation_case_names()));
  r->read("ppp", s.ppp, Need::optional, in_left_open(0.0, 1.0));
  r->read("seed", s.seed);
  r->read("sets", s.sets, Need::optional, at_least(1));
  const bool depth_ok = valid_or_absent(*r, "bit_depth", r->read("bit_depth", s.bit_depth, Need::optional, one_of<int>({12, 16})));
  r->read("noise", s.noise);
  r->read("read_noise_e", s.read_noise_e, Need::optional, at_least(0.0));
  const bool peak_ok =
      valid_or_absent(*r, "peak_counts", r->read("peak_counts", s.peak_counts, Need::optional, greater_than(0.0)));
  r->read_choice("light_sheet", s.light_sheet);
  r->read_choice("spray", s.spray);
  r->read("pulse_b_energy", s.pulse_b_energy, Need::optional, in_left_open(0.0, 2.0));
  // A peak above full scale would clip every particle image.
  if (depth_ok && peak_ok) {
    const double full_scale = static_cast<double>((std::uint64_t{1} << s.bit_depth) - 1);
    if (s.peak_counts > full_scale)
      r->issue("peak_counts", fmt::format("{} must be <= {}, the full scale of bit_depth {}", s.peak_counts,
                                          full_scale, s.bit_depth));
  }
  r->report_unknown_keys();
  simulation = s;
}

}  // namespace detail
}  // namespace tomorig::config
