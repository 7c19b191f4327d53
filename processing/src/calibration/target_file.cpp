// read_target_file: the target description TOML (target_file.h) into a TargetSpec.
#include "tomorig/processing/calibration/target_file.h"

#include <cmath>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "tomorig/config/toml_document.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

class Reader {
 public:
  Reader(config::TomlNode t, std::string file) : t_(t), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw bad_input(fmt::format("target file {}: {} {}", file_, key, problem));
  }
  double number(const char* key, double fallback) const {
    const config::TomlNode n = t_[key];
    if (!n) return fallback;
    const auto v = n.as_double();
    if (!n.is_number() || !v || !std::isfinite(*v)) fail(key, "must be a finite number");
    return *v;
  }
  std::string choice(const char* key, const std::string& fallback, const std::set<std::string>& allowed) const {
    const config::TomlNode n = t_[key];
    if (!n) return fallback;
    const auto v = n.as_string();
    if (!v || !allowed.count(*v)) fail(key, fmt::format("must be one of: {}", fmt::join(allowed, ", ")));
    return *v;
  }
  std::vector<double> numbers(const char* key, std::size_t size) const {
    const config::TomlNode a = t_[key];
    if (!a.is_array() || a.size() != size) fail(key, fmt::format("must be an array of {} numbers", size));
    std::vector<double> out;
    for (std::size_t k = 0; k < size; ++k) {
      const auto v = a[k].as_double();
      if (!a[k].is_number() || !v || !std::isfinite(*v)) fail(key, fmt::format("[{}] must be a finite number", k));
      out.push_back(*v);
    }
    return out;
  }
  bool has(const char* key) const { return t_.contains(key); }

 private:
  config::TomlNode t_;
  std::string file_;
};

}  // namespace

TargetFile read_target_file(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw bad_input(fmt::format("target file {} does not exist", path.string()));
  std::optional<config::TomlDocument> document;
  try {
    document = config::TomlDocument::parse_file(path);
  } catch (const config::TomlSyntaxError& e) {
    throw bad_input(fmt::format("target file {}: line {}: {}", path.string(), e.line(), e.description()));
  }
  const config::TomlNode root = document->root();
  const std::string file = path.string();
  static const std::set<std::string> dot_keys{"kind", "pitch_mm", "lattice", "level_offset_mm", "dots",
                                              "y_axis", "origin_mm", "max_feature_px"};
  static const std::set<std::string> board_keys{"kind", "pitch_mm", "corners"};
  const Reader r(root, file);
  const std::string kind = r.choice("kind", "", {"dots", "chessboard"});
  if (kind.empty()) r.fail("kind", "is missing: dots or chessboard");
  const auto& known = kind == "dots" ? dot_keys : board_keys;
  for (const auto& [key, value] : root.entries())
    if (!known.count(key))
      r.fail(key, fmt::format("is not a key of a {} target; its keys: {}", kind, fmt::join(known, ", ")));
  const double pitch = r.number("pitch_mm", 0);
  if (!(pitch > 0)) r.fail("pitch_mm", "is missing or not > 0: the row pitch (dots) or square size (chessboard), mm");

  TargetFile out;
  if (kind == "chessboard") {
    const std::vector<double> corners = r.numbers("corners", 2);
    ChessboardSpec spec;
    spec.inner_corners_x = static_cast<int>(corners[0]);
    spec.inner_corners_y = static_cast<int>(corners[1]);
    if (spec.inner_corners_x != corners[0] || spec.inner_corners_y != corners[1] || spec.inner_corners_x < 2 ||
        spec.inner_corners_y < 2)
      r.fail("corners", "must be two whole numbers >= 2: the inner corners along x and y");
    spec.square_mm = pitch;
    out.spec = spec;
    return out;
  }
  DotGridSpec spec;
  spec.spacing_mm = pitch;
  spec.lattice = r.choice("lattice", "square", {"square", "staggered"}) == "staggered" ? DotLattice::staggered
                                                                                      : DotLattice::square;
  spec.level_offset_mm = r.number("level_offset_mm", 0);
  if (spec.level_offset_mm != 0 && spec.lattice != DotLattice::staggered)
    r.fail("level_offset_mm", "needs lattice = \"staggered\" (the second level's dots sit between the first's)");
  spec.white_dots = r.choice("dots", "white", {"white", "black"}) == "white";
  out.y_axis = r.choice("y_axis", "auto", {"auto", "down", "up"});
  spec.y_down = out.y_axis != "up";
  if (r.has("origin_mm")) {
    const std::vector<double> o = r.numbers("origin_mm", 3);
    spec.origin_mm = {o[0], o[1], o[2]};
  }
  spec.max_feature_px = r.number("max_feature_px", 0);
  if (spec.max_feature_px < 0) r.fail("max_feature_px", "must be >= 0 (0 = automatic)");
  out.spec = spec;
  return out;
}

}  // namespace tomorig::calibration
