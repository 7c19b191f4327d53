#pragma once
// Shared by the `tomorig bench ...` commands: the machine description every result carries,
// the memory floor measured in the same run, and JSON output.
#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "tomorig/core/frame_set.h"

namespace tomorig::bench {

// The Gaussian smoothing (sigma x,y,z in voxels) the bench commands apply to reconstructed volumes
// before judging them: the sigma that maximises Q for tomorig's volumes at sigma_w 0.6 px
// (docs/accuracy.md, "Smoothing"; the thesis's 0.68,0.68,0.1 is --fmart-smoothing 0.68,0.68,0.1).
inline constexpr const char* kJudgingSmoothingVoxel = "0.6,0.6,0.5";

// {"cpu": ..., "cores": ..., "memory_gb": ..., "software_version": ..., "hostname": ...}
nlohmann::json machine_json();

// Seconds to write and then read back `floats` floats once: the floor any pass over a dense
// volume of that size pays on this machine.
double memory_pass_seconds(std::size_t floats);

// A finite number, or null for inf and NaN (JSON has neither).
nlohmann::json json_number(double value);

// Pretty JSON to `path`, or to stdout when `path` is empty or "-". Written through
// "<path>.partial" and renamed; throws tomorig::Error (bad_input) if it cannot be written.
void write_json(const nlohmann::json& value, const std::string& path);

// A set of `cameras` cameras x 2 exposures of side x side Mono16 frames that look like a
// particle recording (dark noisy background, bright spots), deterministic for `seed`, so that
// compression sees realistic content. Pages are touched, so nothing is backed by the zero page.
FrameSet synthetic_particle_set(int cameras, int side, std::uint64_t seed);
std::uint64_t set_bytes(const FrameSet& set);

// Seconds of CPU used by the whole process (all threads) so far.
double process_cpu_seconds();

}  // namespace tomorig::bench
