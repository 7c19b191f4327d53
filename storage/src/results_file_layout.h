#pragma once
// Names of the results-file layout version 2 (docs/file-formats.md, "Results file"): the sets
// are rows of growing datasets, appended in place under HDF5 SWMR, instead of version 1's one
// group per set (results_layout.h, still read). Shared by the writer and the reader.
#include <cstdint>

namespace tomorig::storage::results_layout_v2 {

inline constexpr int kFormatVersion = 2;

// /sets: one row per set written (attributes nodes, origin_mm, spacing_mm of the shared
// interrogation grid). A row counts only once `complete` holds 1 for it: that byte is written
// and flushed after everything else of the row, and a never-written row reads as 0.
inline constexpr const char* kComplete = "complete";            // uint8 [rows]
inline constexpr const char* kSetIndex = "set_index";           // uint64 [rows]
inline constexpr const char* kDt = "dt_ns";                     // int64 [rows]
inline constexpr const char* kSeconds = "seconds";              // float64 [rows]
inline constexpr const char* kCompleted = "completed_utc";      // fixed 32-byte string [rows]
inline constexpr const char* kReportText = "report_text";       // uint8 [bytes]: the JSON reports, concatenated
inline constexpr const char* kReportSpan = "report_span";       // uint64 [rows, 2]: offset, length in report_text
inline constexpr std::size_t kUtcBytes = 32;

// /statistics/sets (uint64 [1]): the number of sets the statistics cover. 0 while they are
// being rewritten, so a reader can tell stale or torn statistics from current ones.
inline constexpr const char* kStatisticsSets = "sets";

}  // namespace tomorig::storage::results_layout_v2
