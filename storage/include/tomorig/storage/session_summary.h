#pragma once
// A summary of a session for people and scripts (`tomorig inspect`): what was recorded, how
// long it ran, and what is missing.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "tomorig/storage/session_file.h"

namespace tomorig::storage {

struct SessionSummary {
  std::filesystem::path path;
  std::uintmax_t file_size_bytes = 0;
  int format_version = 0;
  std::string software_version;
  std::string created_utc;
  Compression compression = Compression::none;
  std::vector<SessionCamera> cameras;

  std::uint64_t sets = 0;
  int missing_frames = 0;   // of 2 * cameras * sets
  int incomplete_sets = 0;  // sets with at least one missing frame
  // Over all sets; all zero when there are no sets.
  std::int64_t dt_ns_min = 0, dt_ns_max = 0;
  std::int64_t first_trigger_ns = 0, last_trigger_ns = 0;
  double time_span_s = 0.0;  // last - first trigger timestamp
  std::uint64_t first_trigger_index = 0, last_trigger_index = 0;

  // False while a live recording is written or after it was interrupted (a .partial file).
  bool recording_complete = true;

  bool truth = false;  // a simulated session with ground truth
  std::string truth_case, truth_flow;
  std::uint64_t truth_sets = 0;
};

SessionSummary summarize(const SessionReader& reader);

}  // namespace tomorig::storage
