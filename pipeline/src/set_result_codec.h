#pragma once
// The bytes a worker rank sends rank 0 for a finished set: the set's SetResult (vector field,
// pulse separation, report, time) and the figures of its progress line. Plain copies of the
// arrays, no conversion: the field arrives bit for bit as the worker computed it. Both ends are
// the same tomorig binary on the same kind of machine, so no byte-order translation is done.
#include <cstddef>
#include <vector>

#include "tomorig/storage/results_file.h"

namespace tomorig::pipeline {

struct FinishedSet {
  storage::SetResult result;
  std::size_t vectors = 0;      // valid + replaced + invalid
  double valid_fraction = 0.0;  // of the correlator's report
};

std::vector<char> encode_finished_set(const FinishedSet& set);
// Throws tomorig::Error (runtime) for bytes that are not a whole encoded set.
FinishedSet decode_finished_set(const std::vector<char>& bytes);

}  // namespace tomorig::pipeline
