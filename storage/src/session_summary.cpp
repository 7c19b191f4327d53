#include "tomorig/storage/session_summary.h"

#include <algorithm>
#include <cstdint>
#include <system_error>

namespace tomorig::storage {

SessionSummary summarize(const SessionReader& reader) {
  SessionSummary s;
  const SessionInfo& info = reader.info();
  s.path = reader.path();
  std::error_code ec;
  s.file_size_bytes = std::filesystem::file_size(s.path, ec);
  if (ec) s.file_size_bytes = 0;
  s.format_version = reader.format_version();
  s.software_version = info.software_version;
  s.created_utc = info.created_utc;
  s.compression = info.compression;
  s.cameras = info.cameras;
  s.sets = reader.set_count();
  s.missing_frames = reader.missing_frames();
  s.incomplete_sets = reader.incomplete_sets();

  for (std::uint64_t i = 0; i < s.sets; ++i) {
    const SetRecord r = reader.set_record(i);
    if (i == 0) {
      s.dt_ns_min = s.dt_ns_max = r.dt_ns;
      s.first_trigger_ns = s.last_trigger_ns = r.trigger_timestamp_ns;
      s.first_trigger_index = s.last_trigger_index = r.trigger_index;
    }
    s.dt_ns_min = std::min(s.dt_ns_min, r.dt_ns);
    s.dt_ns_max = std::max(s.dt_ns_max, r.dt_ns);
    // Sets are in acquisition order, but a clock may step; span the extremes.
    s.first_trigger_ns = std::min(s.first_trigger_ns, r.trigger_timestamp_ns);
    s.last_trigger_ns = std::max(s.last_trigger_ns, r.trigger_timestamp_ns);
    s.first_trigger_index = std::min(s.first_trigger_index, r.trigger_index);
    s.last_trigger_index = std::max(s.last_trigger_index, r.trigger_index);
  }
  // last >= first, so the difference is in [0, 2^64): exact in unsigned arithmetic, where the
  // signed subtraction would overflow for timestamps far apart (INT64_MIN and INT64_MAX).
  const std::uint64_t span_ns =
      static_cast<std::uint64_t>(s.last_trigger_ns) - static_cast<std::uint64_t>(s.first_trigger_ns);
  s.time_span_s = static_cast<double>(span_ns) * 1e-9;

  s.recording_complete = reader.recording_complete();
  s.truth = reader.has_truth();
  if (s.truth) {
    const SessionTruth truth = reader.truth();
    s.truth_case = truth.case_name;
    s.truth_flow = truth.flow_name;
    s.truth_sets = reader.truth_set_count();
  }
  return s;
}

}  // namespace tomorig::storage
