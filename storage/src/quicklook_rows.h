#pragma once
// A QuickLookRecord as rows of the float tables /quicklook/sets and /quicklook/cameras, and
// back. Columns are found by name on reading, so a file with more (newer) columns still reads,
// and a column it lacks reads as not measured.
#include <span>
#include <string>
#include <vector>

#include "tomorig/storage/quicklook_record.h"

namespace tomorig::storage::detail {

// One row of /quicklook/sets (quicklook_set_columns() order).
void set_row(const QuickLookRecord& record, std::span<float> row);
// One row per camera of /quicklook/cameras (quicklook_camera_columns() order).
void camera_row(const QuickLookCameraRecord& record, std::span<float> row);

// Position of each known column in a file's column list, -1 where the file has none.
std::vector<int> column_positions(const std::vector<std::string_view>& known, const std::vector<std::string>& in_file);
void read_set_row(std::span<const float> row, const std::vector<int>& positions, QuickLookRecord& record);
void read_camera_row(std::span<const float> row, const std::vector<int>& positions, QuickLookCameraRecord& record);

// Folds a later row of the same set into `into`: measured figures replace unmeasured ones (and
// the later of two measured ones wins), flags take the worse, preview and alarms add up.
void merge(QuickLookRecord& into, const QuickLookRecord& later);

}  // namespace tomorig::storage::detail
