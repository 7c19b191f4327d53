#include "tomorig/processing/calibration/target_depths.h"

#include <charconv>
#include <cmath>
#include <fstream>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

constexpr double kKeyUnitMm = 1e-4;  // points closer than this in x and y are the same point

std::pair<long long, long long> key_of(double x_mm, double y_mm) {
  return {std::llround(x_mm / kKeyUnitMm), std::llround(y_mm / kKeyUnitMm)};
}

std::vector<std::string> fields_of(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const auto comma = line.find(',', start);
    std::string field = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto first = field.find_first_not_of(" \t");
    const auto last = field.find_last_not_of(" \t");
    out.push_back(first == std::string::npos ? std::string() : field.substr(first, last - first + 1));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

}  // namespace

TargetDepths read_target_depths(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw bad_input(fmt::format("--target-z {}: cannot open the file", file));
  const std::string expected = "a header X,Y,Z and one row per target point: its world x, y (mm, as --points-out writes "
                               "them) and its z relative to the plate (mm)";
  TargetDepths depths;
  depths.file = file;
  int column[3] = {-1, -1, -1};  // X, Y, Z
  std::size_t field_count = 0;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    const std::vector<std::string> fields = fields_of(line);
    if (field_count == 0) {
      for (std::size_t k = 0; k < fields.size(); ++k) {
        const int which = fields[k] == "X" ? 0 : fields[k] == "Y" ? 1 : fields[k] == "Z" ? 2 : -1;
        if (which < 0 || column[which] >= 0)
          throw bad_input(fmt::format("--target-z {}:{}: header column '{}' is {}; expected {}", file, number, fields[k],
                                      which < 0 ? "unknown" : "repeated", expected));
        column[which] = static_cast<int>(k);
      }
      if (column[0] < 0 || column[1] < 0 || column[2] < 0)
        throw bad_input(fmt::format("--target-z {}:{}: the header '{}' lacks X, Y or Z; expected {}", file, number, line,
                                    expected));
      field_count = fields.size();
      continue;
    }
    if (fields.size() != field_count)
      throw bad_input(fmt::format("--target-z {}:{}: {} fields, the header has {}; expected {}", file, number,
                                  fields.size(), field_count, expected));
    double value[3];
    for (int c = 0; c < 3; ++c) {
      const std::string& text = fields[static_cast<std::size_t>(column[c])];
      const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value[c]);
      if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(value[c]))
        throw bad_input(fmt::format("--target-z {}:{}: {} '{}' is not a number of mm", file, number, "XYZ"[c], text));
    }
    if (!depths.z_mm.emplace(key_of(value[0], value[1]), value[2]).second)
      throw bad_input(fmt::format("--target-z {}:{}: the point ({}, {}) mm is listed twice", file, number, value[0],
                                  value[1]));
  }
  if (depths.z_mm.empty()) throw bad_input(fmt::format("--target-z {}: no target point; expected {}", file, expected));
  return depths;
}

void apply_target_depths(std::span<std::vector<PointCorrespondence>> cameras, const TargetDepths& depths) {
  for (std::size_t c = 0; c < cameras.size(); ++c)
    for (PointCorrespondence& p : cameras[c]) {
      const auto found = depths.z_mm.find(key_of(p.world.x, p.world.y));
      if (found == depths.z_mm.end())
        throw bad_input(fmt::format("camera {}, plane z = {:g} mm: the target point ({:g}, {:g}) mm is not in --target-z "
                                    "{}; the file must list every point of the target by its world x, y (as "
                                    "--points-out writes them, after --y-axis)",
                                    c, p.world.z, p.world.x, p.world.y, depths.file));
      p.world.z += found->second;
    }
}

}  // namespace tomorig::calibration
