#pragma once
// `tomorig reconstruct` of one set: the chosen exposures of a session's set, after the
// preprocessing chain, reconstructed (and smoothed) into a volume file (HDF5 + XDMF for
// ParaView), with an optional intensity-against-depth plot (PNG). The mean over many sets is
// mean_volume.h.
//
//   SetVolumesOptions o{.session = "run.h5", .set = 3, .out = "v.h5"};
//   o.recon.algorithm = "fmart";
//   const SetVolumesReport r = write_set_volumes(o);
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/pipeline/session_geometry.h"

namespace tomorig::pipeline {

struct SetVolumesOptions {
  std::filesystem::path session;
  std::string calib;             // as `reconstruct --calib`; empty: the truth if present, else the rig config's
  std::uint64_t set = 0;
  std::vector<Exposure> exposures{Exposure::A, Exposure::B};  // volumes "a" and "b"
  std::string chain;             // preprocessing preset or chain TOML; empty: none
  ReconstructionChoices recon;   // algorithm, iterations, grid, PSF, threads
  std::vector<double> smooth;    // Gaussian post-smoothing sigma x, y, z (voxel); empty: none
  std::filesystem::path out;     // volume file; its .xdmf sidecar beside it
  std::filesystem::path png;     // intensity against depth, one curve per exposure; empty: none
  bool sparse_only = false;      // no dense export for ParaView
  bool overwrite = false;        // replace existing outputs
};

struct SetVolumesHooks {
  std::function<void(const std::string&)> warning;   // e.g. about the cameras used
  std::function<void(const std::string&)> progress;  // a line per reconstruction and its result
};

struct SetVolumesReport {
  std::filesystem::path out, xdmf;
  nlohmann::json volumes = nlohmann::json::object();  // per volume name: its reconstruction report
};

// Every output is checked before any work (an existing one is refused, bad_input, without
// `overwrite`), the set index against the session. Throws tomorig::Error (bad_input) naming
// what is wrong and the fix.
SetVolumesReport write_set_volumes(const SetVolumesOptions& options, const SetVolumesHooks& hooks = {});

}  // namespace tomorig::pipeline
