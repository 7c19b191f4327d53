#include "tomorig/processing/optics/psf_table.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/core.h>

#include "optics/toml_reader.h"
#include "tomorig/config/toml_document.h"
#include "tomorig/core/error.h"

namespace tomorig::optics {
namespace {

constexpr const char* kPsfTableKind = "psf-table";

std::string list(const std::vector<double>& v, const char* format) {
  std::string out;
  for (double x : v) out += (out.empty() ? "" : ", ") + fmt::format(fmt::runtime(format), x);
  return out;
}

}  // namespace

void PsfTable::validate() const {
  if (!(voxel_mm > 0) || !std::isfinite(voxel_mm)) throw bad_input(fmt::format("PSF table: voxel_mm = {} must be > 0", voxel_mm));
  if (axis != "x" && axis != "y") throw bad_input(fmt::format("PSF table: axis '{}' must be x or y", axis));
  if (cameras.empty()) throw bad_input("PSF table: no cameras");
  for (const PsfTableCamera& c : cameras) {
    const std::size_t n = c.z_mm.size();
    if (n == 0) throw bad_input(fmt::format("PSF table: camera '{}' has no depths", c.id));
    if (c.chi_um.size() != n || c.chi_voxel_um.size() != n || c.sigma_px.size() != n)
      throw bad_input(fmt::format("PSF table: camera '{}': z_mm, chi_um, chi_voxel_um and sigma_px must have one value "
                                  "per depth ({})",
                                  c.id, n));
    for (std::size_t k = 0; k < n; ++k) {
      if (!std::isfinite(c.z_mm[k]) || (k > 0 && !(c.z_mm[k] > c.z_mm[k - 1])))
        throw bad_input(fmt::format("PSF table: camera '{}': z_mm must ascend strictly (z_mm[{}] = {})", c.id, k, c.z_mm[k]));
      if (!(c.chi_um[k] > 0) || !(c.chi_voxel_um[k] > 0) || !(c.sigma_px[k] > 0) || !std::isfinite(c.chi_um[k]) ||
          !std::isfinite(c.chi_voxel_um[k]) || !std::isfinite(c.sigma_px[k]))
        throw bad_input(fmt::format("PSF table: camera '{}' at z = {} mm: chi and sigma must be > 0", c.id, c.z_mm[k]));
    }
  }
}

const PsfTableCamera* PsfTable::find(const std::string& id) const {
  for (const PsfTableCamera& c : cameras)
    if (c.id == id) return &c;
  return nullptr;
}

std::string psf_table_toml(const PsfTable& t, const std::string& header) {
  std::string out;
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);) out += "# " + line + "\n";
  out += fmt::format("kind = \"{}\"\nvoxel_mm = {}\naxis = \"{}\"\n", kPsfTableKind, t.voxel_mm, t.axis);
  for (const PsfTableCamera& c : t.cameras)
    out += fmt::format("\n[[cameras]]\nid = \"{}\"\nz_mm = [{}]\nchi_um = [{}]\nchi_voxel_um = [{}]\nsigma_px = [{}]\n", c.id,
                       list(c.z_mm, "{}"), list(c.chi_um, "{:.2f}"), list(c.chi_voxel_um, "{:.2f}"),
                       list(c.sigma_px, "{:.4f}"));
  return out;
}

PsfTable parse_psf_table(std::string_view toml_text, const std::string& source) {
  std::optional<config::TomlDocument> doc;
  try {
    doc = config::TomlDocument::parse(toml_text, source);
  } catch (const config::TomlSyntaxError& e) {
    throw bad_input(fmt::format("{}: line {}: {}", source, e.line(), e.description()));
  }
  PsfTable t;
  const detail::TomlReader top(source, "", doc->root());
  top.only({"kind", "voxel_mm", "axis", "cameras"});
  if (top.has("kind") && top.string("kind") != kPsfTableKind)
    top.fail("kind", top.node("kind"), fmt::format("must be \"{}\" in a PSF file", kPsfTableKind));
  t.voxel_mm = top.number("voxel_mm");
  if (top.has("axis")) t.axis = top.string("axis");
  const config::TomlNode cams = top.node("cameras");
  if (!cams || !cams.is_array_of_tables() || cams.size() == 0)
    throw bad_input(fmt::format("{}: no [[cameras]]: each camera needs id, z_mm, chi_um, chi_voxel_um and sigma_px "
                                "(written by `tomorig optics psf --psf-out`)",
                                source));
  for (std::size_t i = 0; i < cams.size(); ++i) {
    const detail::TomlReader r(source, fmt::format("cameras[{}]", i), cams[i]);
    r.only({"id", "z_mm", "chi_um", "chi_voxel_um", "sigma_px"});
    PsfTableCamera c;
    c.id = r.string("id");
    c.z_mm = r.numbers("z_mm");
    c.chi_um = r.numbers("chi_um");
    c.chi_voxel_um = r.numbers("chi_voxel_um");
    c.sigma_px = r.numbers("sigma_px");
    t.cameras.push_back(std::move(c));
    try {
      PsfTable one = t;
      one.cameras = {t.cameras.back()};
      one.validate();
    } catch (const Error& e) {
      r.fail("", {}, e.what());
    }
  }
  try {
    t.validate();
  } catch (const Error& e) {
    throw bad_input(fmt::format("{}: {}", source, e.what()));
  }
  return t;
}

PsfTable read_psf_table(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw bad_input(fmt::format("cannot read the PSF file '{}': check the path (`tomorig optics psf --psf-out` "
                                       "writes one)",
                                       path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_psf_table(text.str(), path.string());
}

bool is_psf_table_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return false;
  std::ostringstream text;
  text << in.rdbuf();
  try {
    const config::TomlDocument doc = config::TomlDocument::parse(text.str(), path.string());
    const config::TomlNode kind = doc.root()["kind"];
    if (kind) return kind.as_string() == std::optional<std::string>(kPsfTableKind);
    const config::TomlNode cams = doc.root()["cameras"];
    return cams.is_array_of_tables() && cams.size() > 0 && cams[0].contains("sigma_px");
  } catch (const config::TomlSyntaxError&) {
    return false;
  }
}

}  // namespace tomorig::optics
