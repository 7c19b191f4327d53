// Parsing of the correspondence CSV of correspondence_csv.h: strict, with every error naming
// file, line and column, because these files are often written by hand or by other tools.
#include "tomorig/pipeline/correspondence_csv.h"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::pipeline {
namespace {

enum Column { kCamera, kX, kY, kZ, kPixelX, kPixelY, kPlane, kColumnCount };
constexpr std::array<std::string_view, kColumnCount> kColumnNames = {"camera", "X", "Y", "Z", "x", "y", "plane"};

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  for (;;) {
    const auto comma = line.find(',');
    fields.push_back(trimmed(line.substr(0, comma)));
    if (comma == std::string_view::npos) return fields;
    line.remove_prefix(comma + 1);
  }
}

// Where in the file a field is, for messages: "points.csv:7: column 4 (Z)".
std::string where(const std::filesystem::path& path, int line, int column, Column name) {
  return fmt::format("{}:{}: column {} ({})", path.string(), line, column + 1, kColumnNames[name]);
}

double parse_number(std::string_view field, const std::string& at) {
  double value = 0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (field.empty() || ec != std::errc() || ptr != end || !std::isfinite(value))
    throw bad_input(fmt::format("{}: '{}' is not a finite number; expected a decimal number such as 12.5", at, field));
  return value;
}

int parse_index(std::string_view field, const std::string& at) {
  int value = 0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (field.empty() || ec != std::errc() || ptr != end || value < 0)
    throw bad_input(fmt::format("{}: '{}' is not an index; expected an integer >= 0", at, field));
  return value;
}

bool skipped(std::string_view line) { return line.empty() || line.front() == '#'; }

// Column position of each name in the header (nullopt: absent; only 'plane' may be).
std::array<std::optional<int>, kColumnCount> parse_header(std::string_view header, const std::filesystem::path& path,
                                                          int line) {
  std::array<std::optional<int>, kColumnCount> position;
  const auto fields = split_fields(header);
  for (int k = 0; k < static_cast<int>(fields.size()); ++k) {
    int found = -1;
    for (int c = 0; c < kColumnCount; ++c)
      if (fields[k] == kColumnNames[c]) found = c;
    if (found < 0)
      throw bad_input(fmt::format("{}:{}: column {}: unknown header '{}'; expected the header camera,X,Y,Z,x,y "
                                  "(any order, plus an optional plane column)",
                                  path.string(), line, k + 1, fields[k]));
    if (position[found])
      throw bad_input(fmt::format("{}:{}: column {}: header '{}' appears twice", path.string(), line, k + 1, fields[k]));
    position[found] = k;
  }
  for (int c = 0; c < kPlane; ++c)
    if (!position[c])
      throw bad_input(fmt::format("{}:{}: the header has no '{}' column; expected the header camera,X,Y,Z,x,y "
                                  "(any order, plus an optional plane column)",
                                  path.string(), line, kColumnNames[c]));
  return position;
}

}  // namespace

CorrespondenceTable read_correspondence_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in)
    throw bad_input(fmt::format("point file '{}' does not exist or cannot be read; give a CSV with the header "
                                "camera,X,Y,Z,x,y",
                                path.string()));
  CorrespondenceTable table;
  std::optional<std::array<std::optional<int>, kColumnCount>> columns;
  std::size_t field_count = 0;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    // A UTF-8 byte-order mark (spreadsheets write one) is not part of the first header name.
    if (line == 1 && text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
    const std::string_view row = trimmed(text);
    if (skipped(row)) continue;
    if (!columns) {
      columns = parse_header(row, path, line);
      field_count = split_fields(row).size();
      continue;
    }
    const auto fields = split_fields(row);
    if (fields.size() != field_count)
      throw bad_input(fmt::format("{}:{}: {} fields, expected {} as in the header", path.string(), line, fields.size(),
                                  field_count));
    auto field = [&](Column c) { return fields[static_cast<std::size_t>(*(*columns)[c])]; };
    auto at = [&](Column c) { return where(path, line, *(*columns)[c], c); };
    const int camera = parse_index(field(kCamera), at(kCamera));
    if ((*columns)[kPlane]) parse_index(field(kPlane), at(kPlane));
    calibration::PointCorrespondence point;
    point.world = {parse_number(field(kX), at(kX)), parse_number(field(kY), at(kY)), parse_number(field(kZ), at(kZ))};
    point.pixel = {parse_number(field(kPixelX), at(kPixelX)), parse_number(field(kPixelY), at(kPixelY))};
    if (camera >= static_cast<int>(table.cameras.size())) {
      table.cameras.resize(static_cast<std::size_t>(camera) + 1);
      table.lines.resize(static_cast<std::size_t>(camera) + 1);
    }
    table.cameras[static_cast<std::size_t>(camera)].push_back(point);
    table.lines[static_cast<std::size_t>(camera)].push_back(line);
  }
  if (!columns) throw bad_input(fmt::format("{}: empty file; expected the header camera,X,Y,Z,x,y and one row per point", path.string()));
  if (table.cameras.empty()) throw bad_input(fmt::format("{}: the file has a header but no points", path.string()));
  for (std::size_t i = 0; i < table.cameras.size(); ++i)
    if (table.cameras[i].empty())
      throw bad_input(fmt::format("{}: camera {} has no points, but camera {} has; cameras are numbered 0 to N-1",
                                  path.string(), i, table.cameras.size() - 1));
  return table;
}

void write_correspondence_csv(const std::filesystem::path& path, const CorrespondenceTable& table) {
  std::ofstream out(path);
  if (!out) throw bad_input(fmt::format("cannot write the point file '{}'; check the folder exists and is writable", path.string()));
  out << "camera,X,Y,Z,x,y\n";
  for (std::size_t c = 0; c < table.cameras.size(); ++c)
    for (const auto& p : table.cameras[c])
      out << fmt::format("{},{},{},{},{},{}\n", c, p.world.x, p.world.y, p.world.z, p.pixel.x, p.pixel.y);
  if (!out) throw bad_input(fmt::format("writing the point file '{}' failed", path.string()));
}

}  // namespace tomorig::pipeline
