#pragma once
// `tomorig piv3d`: correlate two given volumes (e.g. the two exposures `tomorig reconstruct`
// wrote, /volumes/a and /volumes/b) into a results file with one set.
#include <functional>
#include <optional>
#include <string>

#include "tomorig/pipeline/correlation_args.h"
#include "tomorig/processing/correlation/correlate.h"

namespace tomorig::pipeline {

struct VolumePairOptions {
  std::string volumes;           // volume file holding volume a (and b, without volume_b)
  std::string volume_b;          // a second volume file holding volume b; empty: `volumes`
  std::string name_a = "a";
  std::string name_b = "b";      // in volume_b, if it has no volume of that name: its first
  std::string out;               // results file
  std::optional<double> dt_ns;   // pulse separation; none: the one recorded in the volume file
  int threads = 0;               // OpenMP threads (0: all cores)
  bool overwrite = false;        // replace an existing results file
  CorrelationArgs correlation;
};

struct VolumePairReport {
  std::string out, xdmf;         // the results file and its ParaView sidecar
  std::string name_b;            // the volume correlated as b
  int nodes[3] = {0, 0, 0};
  piv::CorrelationReport correlation;
};

// Checks the output path (never replaced without `overwrite`), the two volumes' grids and the
// pulse separation before any voxel is read, correlates, and writes the results file.
// `progress` is told (one line of text) when the correlation starts. Throws tomorig::Error
// (bad_input) naming what is wrong and the fix.
VolumePairReport correlate_volume_pair(const VolumePairOptions& options,
                                       const std::function<void(const std::string& message)>& progress = {});

}  // namespace tomorig::pipeline
