#pragma once
// A run's quick-look history as `tomorig inspect` shows it: from the quick-look numbers a
// session stores for its sets (/quicklook), how many sets were measured and how they were
// flagged, each camera's figures over the run (median and range), the light sheet as the
// preview volumes saw it, and a few rows spread over the run.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {

// A figure over the rows that measured it (NaN rows left out).
struct FigureRange {
  std::uint64_t count = 0;
  double min = 0, median = 0, max = 0;
};

struct CameraHistory {
  std::string id;
  FigureRange ppp, diameter_px, source_density;  // frame A
  FigureRange saturated_fraction;                // the larger of A and B
  FigureRange energy_balance, dt_displacement_px, dt_valid_fraction, drift_px;
  std::uint64_t green = 0, amber = 0, red = 0;   // sets by this camera's flag
};

struct QuickLookHistory {
  std::uint64_t sets = 0;      // sets with quick-look numbers
  std::uint64_t previews = 0;  // of them, sets with a preview volume
  std::uint64_t first_set = 0, last_set = 0;
  std::uint64_t green = 0, amber = 0, red = 0;  // sets by their overall flag
  std::uint64_t drift_alarm_sets = 0;           // sets with at least one drift alarm
  std::vector<CameraHistory> cameras;
  FigureRange sheet_position_mm, sheet_thickness_mm, ghost_front, ghost_back, rsnr;
  std::vector<storage::QuickLookRecord> records;  // every stored row, in the order written
};

// From the rows `session` stores; empty (sets == 0) for a session without any.
QuickLookHistory quicklook_history(const storage::SessionReader& session);
QuickLookHistory quicklook_history(std::vector<storage::QuickLookRecord> records,
                                   const std::vector<storage::SessionCamera>& cameras);

// {"sets", "previews", "first_set", "last_set", "flags", "drift_alarm_sets", "cameras", "sheet",
// "history"}: docs/cli.md (inspect). "history" holds every row.
nlohmann::json to_json(const QuickLookHistory& history);
// Lines for inspect's text output: counts, a table per camera, the sheet, and up to `rows`
// rows spread evenly over the run. Empty text for an empty history.
std::string history_text(const QuickLookHistory& history, int rows = 10);

}  // namespace tomorig::pipeline
