#include "quicklook_rows.h"

#include <algorithm>
#include <cmath>

namespace tomorig::storage {
namespace {

// Each column with how it is read from and written to a record: one list, so that the names,
// the order and the fields cannot drift apart.
template <typename Record>
struct Column {
  std::string_view name;
  float (*get)(const Record&);
  void (*put)(Record&, float);
};

float flag_value(std::uint8_t f) { return static_cast<float>(f); }
std::uint8_t flag_of(float v) { return std::isfinite(v) && v >= 0 && v <= 2 ? static_cast<std::uint8_t>(v) : 2; }

#define TOMORIG_FLOAT(Record, name, field) \
  Column<Record> { name, [](const Record& r) { return r.field; }, [](Record& r, float v) { r.field = v; } }

const std::vector<Column<QuickLookRecord>>& set_columns() {
  static const std::vector<Column<QuickLookRecord>> columns = {
      {"flag", [](const QuickLookRecord& r) { return flag_value(r.flag); },
       [](QuickLookRecord& r, float v) { r.flag = flag_of(v); }},
      {"preview", [](const QuickLookRecord& r) { return r.preview ? 1.0f : 0.0f; },
       [](QuickLookRecord& r, float v) { r.preview = v == 1.0f; }},
      TOMORIG_FLOAT(QuickLookRecord, "sheet_position_mm", sheet_position_mm),
      TOMORIG_FLOAT(QuickLookRecord, "sheet_thickness_mm", sheet_thickness_mm),
      TOMORIG_FLOAT(QuickLookRecord, "ghost_front", ghost_front),
      TOMORIG_FLOAT(QuickLookRecord, "ghost_back", ghost_back),
      TOMORIG_FLOAT(QuickLookRecord, "rsnr", rsnr),
      {"drift_alarms", [](const QuickLookRecord& r) { return static_cast<float>(r.drift_alarms); },
       [](QuickLookRecord& r, float v) {
         r.drift_alarms = std::isfinite(v) && v > 0 ? static_cast<std::uint16_t>(std::min(v, 65535.0f)) : 0;
       }},
  };
  return columns;
}

const std::vector<Column<QuickLookCameraRecord>>& camera_columns() {
  using R = QuickLookCameraRecord;
  static const std::vector<Column<R>> columns = {
      {"flag", [](const R& r) { return flag_value(r.flag); }, [](R& r, float v) { r.flag = flag_of(v); }},
      TOMORIG_FLOAT(R, "ppp_a", ppp[0]),
      TOMORIG_FLOAT(R, "ppp_b", ppp[1]),
      TOMORIG_FLOAT(R, "diameter_px_a", diameter_px[0]),
      TOMORIG_FLOAT(R, "diameter_px_b", diameter_px[1]),
      TOMORIG_FLOAT(R, "source_density_a", source_density[0]),
      TOMORIG_FLOAT(R, "source_density_b", source_density[1]),
      TOMORIG_FLOAT(R, "saturated_fraction_a", saturated_fraction[0]),
      TOMORIG_FLOAT(R, "saturated_fraction_b", saturated_fraction[1]),
      TOMORIG_FLOAT(R, "background_a", background[0]),
      TOMORIG_FLOAT(R, "background_b", background[1]),
      TOMORIG_FLOAT(R, "noise_a", noise[0]),
      TOMORIG_FLOAT(R, "noise_b", noise[1]),
      TOMORIG_FLOAT(R, "soft_tile_fraction_a", soft_tile_fraction[0]),
      TOMORIG_FLOAT(R, "soft_tile_fraction_b", soft_tile_fraction[1]),
      TOMORIG_FLOAT(R, "energy_balance", energy_balance),
      TOMORIG_FLOAT(R, "dt_displacement_px", dt_displacement_px),
      TOMORIG_FLOAT(R, "dt_valid_fraction", dt_valid_fraction),
      TOMORIG_FLOAT(R, "drift_px", drift_px),
  };
  return columns;
}

#undef TOMORIG_FLOAT

template <typename Record>
std::vector<std::string_view> names_of(const std::vector<Column<Record>>& columns) {
  std::vector<std::string_view> names;
  for (const auto& c : columns) names.push_back(c.name);
  return names;
}

}  // namespace

const std::vector<std::string_view>& quicklook_set_columns() {
  static const std::vector<std::string_view> names = names_of(set_columns());
  return names;
}

const std::vector<std::string_view>& quicklook_camera_columns() {
  static const std::vector<std::string_view> names = names_of(camera_columns());
  return names;
}

namespace detail {

void set_row(const QuickLookRecord& record, std::span<float> row) {
  const auto& columns = set_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) row[i] = columns[i].get(record);
}

void camera_row(const QuickLookCameraRecord& record, std::span<float> row) {
  const auto& columns = camera_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) row[i] = columns[i].get(record);
}

std::vector<int> column_positions(const std::vector<std::string_view>& known, const std::vector<std::string>& in_file) {
  std::vector<int> positions;
  for (const std::string_view name : known) {
    const auto it = std::find(in_file.begin(), in_file.end(), name);
    positions.push_back(it == in_file.end() ? -1 : static_cast<int>(it - in_file.begin()));
  }
  return positions;
}

void read_set_row(std::span<const float> row, const std::vector<int>& positions, QuickLookRecord& record) {
  const auto& columns = set_columns();
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (positions[i] >= 0) columns[i].put(record, row[static_cast<std::size_t>(positions[i])]);
}

void read_camera_row(std::span<const float> row, const std::vector<int>& positions, QuickLookCameraRecord& record) {
  const auto& columns = camera_columns();
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (positions[i] >= 0) columns[i].put(record, row[static_cast<std::size_t>(positions[i])]);
}

namespace {
void take(float& into, float later) {
  if (std::isfinite(later)) into = later;
}
}  // namespace

void merge(QuickLookRecord& into, const QuickLookRecord& later) {
  into.flag = std::max(into.flag, later.flag);
  into.preview = into.preview || later.preview;
  for (auto f : {&QuickLookRecord::sheet_position_mm, &QuickLookRecord::sheet_thickness_mm, &QuickLookRecord::ghost_front,
                 &QuickLookRecord::ghost_back, &QuickLookRecord::rsnr})
    take(into.*f, later.*f);
  into.drift_alarms = std::max(into.drift_alarms, later.drift_alarms);
  for (std::size_t c = 0; c < std::min(into.cameras.size(), later.cameras.size()); ++c) {
    QuickLookCameraRecord& a = into.cameras[c];
    const QuickLookCameraRecord& b = later.cameras[c];
    a.flag = std::max(a.flag, b.flag);
    for (int e = 0; e < 2; ++e) {
      take(a.ppp[e], b.ppp[e]);
      take(a.diameter_px[e], b.diameter_px[e]);
      take(a.source_density[e], b.source_density[e]);
      take(a.saturated_fraction[e], b.saturated_fraction[e]);
      take(a.background[e], b.background[e]);
      take(a.noise[e], b.noise[e]);
      take(a.soft_tile_fraction[e], b.soft_tile_fraction[e]);
    }
    for (auto f : {&QuickLookCameraRecord::energy_balance, &QuickLookCameraRecord::dt_displacement_px,
                   &QuickLookCameraRecord::dt_valid_fraction, &QuickLookCameraRecord::drift_px})
      take(a.*f, b.*f);
  }
}

}  // namespace detail
}  // namespace tomorig::storage
