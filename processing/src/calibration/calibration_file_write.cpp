// Writing the calibration file. Numbers are printed by fmt's shortest round-trip form, so
// a loaded model reproduces the saved one bit for bit.
#include <fstream>
#include <string>

#include <fmt/core.h>

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

// A TOML float: shortest exact decimal, with a '.' so that it does not read back as an integer.
std::string number(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

template <typename Range>
std::string array(const Range& values) {
  std::string s = "[";
  bool first = true;
  for (double v : values) {
    s += (first ? "" : ", ") + number(v);
    first = false;
  }
  return s + "]";
}

void write_normalization(std::string& out, const Normalization& n) {
  out += "\n[camera.normalization]\n";
  out += fmt::format("world_centre = {}\n", array(std::array{n.world_centre.x, n.world_centre.y, n.world_centre.z}));
  out += fmt::format("world_scale = {}\n", number(n.world_scale));
  out += fmt::format("image_centre = {}\n", array(std::array{n.image_centre.x, n.image_centre.y}));
  out += fmt::format("image_scale = {}\n", number(n.image_scale));
}

// The normalisation a model evaluates with, if it has one; else the one its fit used.
const Normalization& normalization_of(const CameraModel& model, const FitReport& report) {
  if (const auto* d = dynamic_cast<const DltCamera*>(&model)) return d->normalization();
  if (const auto* q = dynamic_cast<const PolynomialCamera*>(&model)) return q->normalization();
  if (const auto* t = dynamic_cast<const TwoPlaneCamera*>(&model)) return t->normalization();
  return report.normalization;
}

void write_lens(std::string& out, const LensCamera& l) {
  const auto& p = l.pinhole().parameters();
  const auto& d = l.distortion();
  out += fmt::format("fx = {}\nfy = {}\ncx = {}\ncy = {}\n", number(p.fx), number(p.fy), number(p.cx), number(p.cy));
  out += fmt::format("R = {}\nt = {}\n", array(p.R), array(std::array{p.t.x, p.t.y, p.t.z}));
  out += fmt::format("radial = {}\ntangential = {}\n", array(std::array{d.k1, d.k2, d.k3}), array(std::array{d.p1, d.p2}));
}

void write_model(std::string& out, const CameraModel& model, int id) {
  if (const auto* m = dynamic_cast<const PinholeCamera*>(&model)) {
    const auto& p = m->parameters();
    out += "\n[camera.coefficients]\n";
    out += fmt::format("fx = {}\nfy = {}\ncx = {}\ncy = {}\n", number(p.fx), number(p.fy), number(p.cx), number(p.cy));
    out += fmt::format("R = {}\nt = {}\n", array(p.R), array(std::array{p.t.x, p.t.y, p.t.z}));
  } else if (const auto* l = dynamic_cast<const LensCamera*>(&model)) {
    out += "\n[camera.coefficients]\n";
    write_lens(out, *l);
  } else if (const auto* rc = dynamic_cast<const RefractiveCamera*>(&model)) {
    out += "\n[camera.coefficients]\n";
    write_lens(out, rc->lens());
    const FlatWindow& w = rc->window();
    out += fmt::format("window_normal = {}\nwindow_medium_face_mm = {}\nwindow_thickness_mm = {}\n",
                       array(std::array{w.normal.x, w.normal.y, w.normal.z}), number(w.medium_face_mm),
                       number(w.thickness_mm));
    out += fmt::format("n_air = {}\nn_window = {}\nn_medium = {}\n", number(w.n_air), number(w.n_window), number(w.n_medium));
  } else if (const auto* d = dynamic_cast<const DltCamera*>(&model)) {
    out += fmt::format("\n[camera.coefficients]\nmatrix = {}\n", array(d->matrix()));
  } else if (const auto* q = dynamic_cast<const PolynomialCamera*>(&model)) {
    out += fmt::format("\n[camera.coefficients]\nnewton_steps = {}\nforward = {}\ninverse = {}\n", q->newton_steps(),
                       array(q->forward_coefficients()), array(q->inverse_coefficients()));
  } else if (const auto* t = dynamic_cast<const TwoPlaneCamera*>(&model)) {
    out += fmt::format("\n[camera.coefficients]\nnewton_steps = {}\n", t->newton_steps());
    for (const auto& plane : t->planes())
      out += fmt::format("\n[[camera.coefficients.planes]]\nz = {}\nto_world = {}\nto_image = {}\n", number(plane.z),
                         array(plane.to_world), array(plane.to_image));
  } else {
    throw bad_input(fmt::format("calibration file: camera {}: the {} model cannot be saved", id, model.model_name()));
  }
}

void write_report(std::string& out, const FitReport& r) {
  out += "\n[camera.fit]\n";
  out += fmt::format("points = {}\nplanes = {}\n", r.points, r.planes);
  out += fmt::format("forward_rms_px = {}\nforward_mean_px = {}\nforward_max_px = {}\n", number(r.forward_rms_px),
                     number(r.forward_mean_px), number(r.forward_max_px));
  out += fmt::format("reverse_rms_um = {}\nreverse_mean_um = {}\nreverse_max_um = {}\n", number(r.reverse_rms_um),
                     number(r.reverse_mean_um), number(r.reverse_max_um));
  if (r.inverse_mapping_mean_um) out += fmt::format("inverse_mapping_mean_um = {}\n", number(*r.inverse_mapping_mean_um));
  out += fmt::format("iterations = {}\nconverged = {}\n", r.iterations, r.converged ? "true" : "false");
}

}  // namespace

void save_calibration(const std::filesystem::path& path, const std::vector<CameraCalibration>& cameras) {
  std::string out = "# tomorig calibration file (docs/calibration.md)\nformat = \"tomorig-calibration\"\nversion = 1\n";
  for (const auto& cam : cameras) {
    if (!cam.model) throw bad_input(fmt::format("calibration file: camera {} has no model", cam.id));
    out += fmt::format("\n[[camera]]\nid = {}\nmodel = \"{}\"\nimage_width = {}\nimage_height = {}\n", cam.id,
                       cam.model->model_name(), cam.image_size.width, cam.image_size.height);
    write_normalization(out, normalization_of(*cam.model, cam.report));
    write_model(out, *cam.model, cam.id);
    write_report(out, cam.report);
  }
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw runtime_error(fmt::format("cannot write the calibration file {}", path.string()));
  file << out;
  file.close();
  if (!file) throw runtime_error(fmt::format("writing the calibration file {} failed", path.string()));
}

}  // namespace tomorig::calibration
