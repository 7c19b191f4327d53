// Reading the calibration file: every value is checked, and a problem names the camera and
// the key, so that a hand-edited or truncated file is refused before it can mis-project.
#include <cmath>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "tomorig/config/toml_document.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/dlt_camera.h"
#include "tomorig/processing/calibration/lens_camera.h"
#include "tomorig/processing/calibration/refractive_camera.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/calibration/polynomial_camera.h"
#include "tomorig/processing/calibration/two_plane_camera.h"

namespace tomorig::calibration {
namespace {

// Reads values of one camera's tables, naming "<file>: camera <id>: <key>" in every error.
class CameraReader {
 public:
  explicit CameraReader(std::string where) : where_(std::move(where)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw bad_input(fmt::format("{}: {} {}", where_, key, problem));
  }

  config::TomlNode table(config::TomlNode parent, const std::string& prefix, const char* key) const {
    const config::TomlNode t = parent[key];
    if (!t.is_table()) fail(prefix + key, "is missing (or is not a table)");
    return t;
  }

  double number(config::TomlNode t, const std::string& prefix, const char* key) const {
    return number_of(t[key], prefix + key);
  }

  std::int64_t integer(config::TomlNode t, const std::string& prefix, const char* key) const {
    const auto v = t[key].as_integer();
    if (!t[key].is_integer() || !v) fail(prefix + key, t[key] ? "must be an integer" : "is missing");
    return *v;
  }

  bool boolean(config::TomlNode t, const std::string& prefix, const char* key) const {
    const auto v = t[key].as_bool();
    if (!v) fail(prefix + key, t[key] ? "must be true or false" : "is missing");
    return *v;
  }

  std::string string(config::TomlNode t, const std::string& prefix, const char* key) const {
    const auto v = t[key].as_string();
    if (!v) fail(prefix + key, t[key] ? "must be a string" : "is missing");
    return *v;
  }

  // An array of exactly `size` finite numbers (size < 0: any length >= 1).
  std::vector<double> numbers(config::TomlNode t, const std::string& prefix, const char* key, int size) const {
    const std::string name = prefix + key;
    const config::TomlNode a = t[key];
    if (!a.is_array()) fail(name, a ? "must be an array of numbers" : "is missing");
    if (size >= 0 && static_cast<int>(a.size()) != size)
      fail(name, fmt::format("has {} values, expected {}", a.size(), size));
    std::vector<double> out;
    for (std::size_t k = 0; k < a.size(); ++k) out.push_back(number_of(a[k], fmt::format("{}[{}]", name, k)));
    return out;
  }

 private:
  double number_of(config::TomlNode node, const std::string& name) const {
    if (!node) fail(name, "is missing");
    if (!node.is_number()) fail(name, "must be a number");
    const double v = node.as_double().value_or(std::nan(""));
    if (!std::isfinite(v)) fail(name, fmt::format("is {}: every coefficient must be finite", v));
    return v;
  }

  std::string where_;
};

Normalization read_normalization(const CameraReader& r, config::TomlNode cam) {
  const config::TomlNode t = r.table(cam, "", "normalization");
  const std::string p = "normalization.";
  Normalization n;
  const auto wc = r.numbers(t, p, "world_centre", 3);
  const auto ic = r.numbers(t, p, "image_centre", 2);
  n.world_centre = {wc[0], wc[1], wc[2]};
  n.image_centre = {ic[0], ic[1]};
  n.world_scale = r.number(t, p, "world_scale");
  n.image_scale = r.number(t, p, "image_scale");
  if (!(n.world_scale > 0)) r.fail(p + "world_scale", "must be > 0");
  if (!(n.image_scale > 0)) r.fail(p + "image_scale", "must be > 0");
  return n;
}

FitReport read_report(const CameraReader& r, config::TomlNode cam, const std::string& model, int id) {
  const config::TomlNode t = r.table(cam, "", "fit");
  const std::string p = "fit.";
  FitReport rep;
  rep.model = model;
  rep.camera = fmt::format("camera {}", id);
  rep.points = static_cast<int>(r.integer(t, p, "points"));
  rep.planes = static_cast<int>(r.integer(t, p, "planes"));
  rep.forward_mean_px = r.number(t, p, "forward_mean_px");
  rep.forward_max_px = r.number(t, p, "forward_max_px");
  rep.reverse_mean_um = r.number(t, p, "reverse_mean_um");
  rep.reverse_max_um = r.number(t, p, "reverse_max_um");
  // RMS since issue 18; older files have the mean only, which then stands in for it.
  rep.forward_rms_px = t.contains("forward_rms_px") ? r.number(t, p, "forward_rms_px") : rep.forward_mean_px;
  rep.reverse_rms_um = t.contains("reverse_rms_um") ? r.number(t, p, "reverse_rms_um") : rep.reverse_mean_um;
  if (t.contains("inverse_mapping_mean_um")) rep.inverse_mapping_mean_um = r.number(t, p, "inverse_mapping_mean_um");
  rep.iterations = static_cast<int>(r.integer(t, p, "iterations"));
  rep.converged = r.boolean(t, p, "converged");
  return rep;
}

int newton_steps(const CameraReader& r, config::TomlNode c, const std::string& p) {
  const auto steps = r.integer(c, p, "newton_steps");
  if (steps < 0 || steps > 50) r.fail(p + "newton_steps", fmt::format("= {} must be in [0, 50]", steps));
  return static_cast<int>(steps);
}

// Builds a model from values already read; a constructor's complaint (e.g. R is not a
// rotation) still names the camera.
template <typename Make>
std::shared_ptr<const CameraModel> construct(const CameraReader& r, Make make) {
  try {
    return make();
  } catch (const Error& e) {
    r.fail("coefficients", fmt::format("are invalid: {}", e.what()));
  }
}

std::shared_ptr<const CameraModel> read_model(const CameraReader& r, config::TomlNode cam, const std::string& model,
                                              const Normalization& n) {
  const config::TomlNode c = r.table(cam, "", "coefficients");
  const std::string p = "coefficients.";
  if (model == "pinhole" || model == "pinhole_distortion" || model == "refractive") {
    PinholeParameters pp;
    pp.fx = r.number(c, p, "fx");
    pp.fy = r.number(c, p, "fy");
    pp.cx = r.number(c, p, "cx");
    pp.cy = r.number(c, p, "cy");
    const auto R = r.numbers(c, p, "R", 9);
    const auto t = r.numbers(c, p, "t", 3);
    std::copy(R.begin(), R.end(), pp.R.begin());
    pp.t = {t[0], t[1], t[2]};
    if (model == "pinhole") return construct(r, [&] { return std::make_shared<PinholeCamera>(pp); });
    const auto k = r.numbers(c, p, "radial", 3);
    const auto tangential = r.numbers(c, p, "tangential", 2);
    const LensDistortion d{k[0], k[1], k[2], tangential[0], tangential[1]};
    if (model == "pinhole_distortion") return construct(r, [&] { return std::make_shared<LensCamera>(pp, d); });
    FlatWindow w;
    const auto normal = r.numbers(c, p, "window_normal", 3);
    w.normal = {normal[0], normal[1], normal[2]};
    w.medium_face_mm = r.number(c, p, "window_medium_face_mm");
    w.thickness_mm = r.number(c, p, "window_thickness_mm");
    w.n_air = r.number(c, p, "n_air");
    w.n_window = r.number(c, p, "n_window");
    w.n_medium = r.number(c, p, "n_medium");
    return construct(r, [&] { return std::make_shared<RefractiveCamera>(LensCamera(pp, d), w); });
  }
  if (model == "dlt") {
    const auto a = r.numbers(c, p, "matrix", 12);
    Mat34d m;
    std::copy(a.begin(), a.end(), m.begin());
    return construct(r, [&] { return std::make_shared<DltCamera>(m, n); });
  }
  if (model == "rational2" || model == "soloff3") {
    const PolynomialKind kind = model == "rational2" ? PolynomialKind::rational2 : PolynomialKind::soloff3;
    const int count = PolynomialCamera::coefficient_count(kind);
    auto forward = r.numbers(c, p, "forward", count);
    auto inverse = r.numbers(c, p, "inverse", count);
    const int steps = newton_steps(r, c, p);
    return construct(r, [&] { return std::make_shared<PolynomialCamera>(kind, n, forward, inverse, steps); });
  }
  if (model == "twoplane") {
    const config::TomlNode planes = c["planes"];
    if (!planes.is_array() || planes.size() < 2) r.fail(p + "planes", "must be an array of at least 2 plane tables");
    std::vector<TwoPlaneMapping> mappings;
    for (std::size_t k = 0; k < planes.size(); ++k) {
      const config::TomlNode t = planes[k];
      const std::string pk = fmt::format("{}planes[{}].", p, k);
      if (!t.is_table()) r.fail(pk.substr(0, pk.size() - 1), "must be a table");
      mappings.push_back({r.number(t, pk, "z"), r.numbers(t, pk, "to_world", TwoPlaneCamera::kCoefficientsPerMapping),
                          r.numbers(t, pk, "to_image", TwoPlaneCamera::kCoefficientsPerMapping)});
    }
    const int steps = newton_steps(r, c, p);
    return construct(r, [&] { return std::make_shared<TwoPlaneCamera>(n, mappings, steps); });
  }
  r.fail("model", fmt::format("= \"{}\" is not a known model (pinhole, dlt, pinhole_distortion, refractive, twoplane, rational2, soloff3)", model));
}

}  // namespace

std::vector<CameraCalibration> load_calibration(const std::filesystem::path& path) {
  std::optional<config::TomlDocument> doc;
  try {
    doc = config::TomlDocument::parse_file(path);
  } catch (const config::TomlSyntaxError& e) {
    if (!std::filesystem::exists(path))
      throw bad_input(fmt::format("calibration file {} does not exist", path.string()));
    throw bad_input(fmt::format("calibration file {}: line {}: {}", path.string(), e.line(), e.description()));
  }
  const config::TomlNode root = doc->root();
  const std::string file = path.string();
  if (root["format"].as_string() != "tomorig-calibration")
    throw bad_input(fmt::format("{}: not a tomorig calibration file (format = \"tomorig-calibration\" is missing)", file));
  if (root["version"].as_integer() != 1)
    throw bad_input(fmt::format("{}: unsupported version (this tomorig reads version = 1)", file));
  const config::TomlNode cameras = root["camera"];
  if (!cameras.is_array() || cameras.size() == 0) throw bad_input(fmt::format("{}: no [[camera]] entries", file));

  std::vector<CameraCalibration> out;
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    const config::TomlNode cam = cameras[k];
    if (!cam.is_table()) throw bad_input(fmt::format("{}: camera entry {} is not a table", file, k));
    const CameraReader entry(fmt::format("{}: camera entry {}", file, k));
    CameraCalibration c;
    c.id = static_cast<int>(entry.integer(cam, "", "id"));
    for (const auto& seen : out)
      if (seen.id == c.id) entry.fail("id", fmt::format("= {} is used by two cameras", c.id));
    const CameraReader r(fmt::format("{}: camera {}", file, c.id));
    c.image_size = {static_cast<int>(r.integer(cam, "", "image_width")), static_cast<int>(r.integer(cam, "", "image_height"))};
    if (c.image_size.width <= 0 || c.image_size.height <= 0) r.fail("image_width/image_height", "must be > 0");
    const std::string model = r.string(cam, "", "model");
    const Normalization n = read_normalization(r, cam);
    c.model = read_model(r, cam, model, n);
    c.report = read_report(r, cam, model, c.id);
    c.report.normalization = n;
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace tomorig::calibration
