#pragma once
// The droplets of a spray-thesis session's truth (issue 20): positions from /truth/sets, and the
// diameters the truth does not always hold (a live run records none; `simulate` keeps the sets
// that fit in 64 KiB) regenerated from the recorded options, as sim::spray_droplets does for
// the renderer.
#include <cstdint>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/simulators/spray.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::bench {

struct TruthDroplet {
  Vec3d a, b;  // world mm at pulses A and B (the recorded pulse separation)
  double d_um = 0;
};

// The case a session's truth was rendered with. Throws bad_input if the session is not a
// spray-thesis recording (no truth, another case, options missing).
sim::SprayCase spray_case_of(const storage::SessionTruth& truth);

// Set `set_index`'s droplets: positions from the truth set, diameters from the case at the set's
// trigger index. Throws bad_input if the truth set is missing or does not match the case.
std::vector<TruthDroplet> spray_truth_droplets(const storage::SessionReader& session, const sim::SprayCase& c,
                                               std::uint64_t set_index);

}  // namespace tomorig::bench
