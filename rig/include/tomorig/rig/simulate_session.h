#pragma once
// Renders the simulated rig of a rig config into an HDF5 session with ground truth. Shared by
// `tomorig simulate` and `tomorig run` (on a rig whose cameras are all simulated).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "tomorig/config/rig_config.h"
#include "tomorig/simulators/simulated_rig.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

struct SimulationSummary {
  std::string case_name;
  std::uint64_t sets = 0;
  std::size_t cameras = 0;
  std::size_t particles_per_set = 0;
  double seconds = 0.0;  // wall time: rendering + writing
  std::filesystem::path output;
  std::uintmax_t bytes = 0;  // size of the finished file

  // One line for the terminal, e.g. "wrote s.h5: tpiv-thesis, 2 sets x 4 cameras, ...".
  std::string brief() const;
};

// Called after each set is rendered and written: `done` of `total` sets, and the seconds since
// the previous set was written (rendering overlaps writing, so this is the cost per set).
using SimulationProgress = std::function<void(std::uint64_t done, std::uint64_t total, double set_seconds)>;

// The truth record of a simulated camera: its pinhole's K, R, t and image size (the model name
// only where the pinhole is the whole camera, as in the simulated rig).
storage::TruthCamera truth_camera_of(const std::string& id, const calibration::PinholeCamera& model, int width,
                                     int height);
storage::TruthCamera truth_camera_of(const sim::SimulatedCamera& cam);

// The simulator options a rig config describes: its [simulation] section, its cameras (all
// must use the simulated backend, their pixel formats must match simulation.bit_depth) and
// its trigger rate and pulse separation. Throws tomorig::Error (bad_input) naming the key.
sim::SimulationOptions simulation_options_from(const config::RigConfig& rig);

// Renders rig.simulation->sets sets and writes them, the rig's TOML text and the truth to
// `out` through storage::SessionWriter. Everything is validated before the file is created.
// `should_stop` (optional) is asked between sets; when it says true, the sets written so far are
// finished into a complete session (summary.sets says how many).
// `live`: record as a running rig does (storage::SessionWriterOptions::live): readable while
// written, flushed as it goes, and an interrupted run keeps its sets in "<out>.partial".
SimulationSummary run_simulation_to_session(const config::RigConfig& rig, const std::filesystem::path& out,
                                            storage::Compression compression, bool overwrite,
                                            const SimulationProgress& progress = {}, bool live = false,
                                            const std::function<bool()>& should_stop = {});

}  // namespace tomorig::rig
