#include "tomorig/processing/optics/optics_setup.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/core.h>

#include "optics/toml_reader.h"
#include "tomorig/config/toml_document.h"
#include "tomorig/core/error.h"

namespace tomorig::optics {

using TomlReader = detail::TomlReader;

VisibilitySetup parse_optics_setup(std::string_view toml_text, const std::string& source) {
  std::optional<config::TomlDocument> doc;
  try {
    doc = config::TomlDocument::parse(toml_text, source);
  } catch (const config::TomlSyntaxError& e) {
    throw bad_input(fmt::format("{}: line {}: {}", source, e.line(), e.description()));
  }
  VisibilitySetup setup;
  const TomlReader top(source, "", doc->root());
  top.only({"liquid", "led", "cameras", "d_max_um"});
  if (top.has("liquid")) {
    try {
      setup.liquid = Liquid::named(top.string("liquid"));
    } catch (const Error& e) {
      top.fail("liquid", top.node("liquid"), e.what());
    }
  }
  if (top.has("d_max_um")) setup.d_max_um = top.number("d_max_um");
  if (const config::TomlNode led = top.node("led")) {
    if (!led.is_table()) top.fail("led", led, "must be a table ([led])");
    const TomlReader r(source, "led", led);
    r.only({"peak_nm", "fwhm_nm", "samples"});
    if (r.has("peak_nm")) setup.spectrum.peak_nm = r.number("peak_nm");
    if (r.has("fwhm_nm")) setup.spectrum.fwhm_nm = r.number("fwhm_nm");
    if (r.has("samples")) setup.spectrum.samples = static_cast<int>(r.number("samples"));
    try {
      setup.spectrum.validate();
    } catch (const Error& e) {
      r.fail("", {}, e.what());
    }
  }
  const config::TomlNode cams = top.node("cameras");
  if (!cams || !cams.is_array_of_tables() || cams.size() == 0)
    throw bad_input(fmt::format("{}: no [[cameras]]: give each camera's id, f_number, magnification, noise (or "
                                "threshold), z_mm and chi_um",
                                source));
  for (std::size_t i = 0; i < cams.size(); ++i) {
    const TomlReader r(source, fmt::format("cameras[{}]", i), cams[i]);
    r.only({"id", "f_number", "magnification", "noise", "threshold", "z_mm", "chi_um"});
    CameraOptics c;
    c.id = r.has("id") ? r.string("id") : fmt::format("camera {}", i + 1);
    c.f_number = r.number("f_number");
    c.magnification = r.number("magnification");
    if (r.has("noise") == r.has("threshold"))
      r.fail("", {}, "give exactly one of noise (sigma of the flat-fielded bright field) or threshold (1 - 2 sigma)");
    c.noise_sigma = r.has("noise") ? r.number("noise") : 0.5 * (1.0 - r.number("threshold"));
    const std::vector<double> z = r.numbers("z_mm"), chi = r.numbers("chi_um");
    if (z.size() != chi.size())
      r.fail("chi_um", r.node("chi_um"), fmt::format("has {} values but z_mm has {}: one chi per depth", chi.size(), z.size()));
    for (std::size_t k = 0; k < z.size(); ++k) c.chi.push_back({z[k], chi[k]});
    setup.cameras.push_back(std::move(c));
    try {
      VisibilitySetup one;
      one.cameras = {setup.cameras.back()};
      one.validate();
    } catch (const Error& e) {
      r.fail("", {}, e.what());
    }
  }
  try {
    setup.validate();
  } catch (const Error& e) {
    throw bad_input(fmt::format("{}: {}", source, e.what()));
  }
  return setup;
}

VisibilitySetup read_optics_setup(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw bad_input(fmt::format("cannot read the optics set-up file '{}': check the path", path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_optics_setup(text.str(), path.string());
}

}  // namespace tomorig::optics
