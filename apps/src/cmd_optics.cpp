// tomorig optics: the droplet imaging model of tomographic shadowgraphy (docs/spray.md).
//   tomorig optics visibility --setup optics.toml [--json] [--png plot.png] [--overwrite]
//   tomorig optics visibility --f-number 22 --magnification 0.9 --chi -4.5:62,0:40,4.5:60 --noise 0.01
//   tomorig optics transmission --f-number 22 --magnification 0.9 --d 5,10,20,50 [--chi 40]
//   tomorig optics psf targets.h5 [--calib truth|FILE] [--grid G] [--z LIST] [--json] [--png P] [--psf-out psf.toml]
#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"
#include "tomorig/processing/optics/edge_psf.h"
#include "tomorig/processing/optics/optics_setup.h"
#include "tomorig/processing/optics/psf_plot.h"
#include "tomorig/processing/optics/psf_table.h"
#include "tomorig/processing/optics/visibility.h"
#include "tomorig/processing/optics/visibility_plot.h"
#include "tomorig/processing/optics/voxel_psf.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/output_path.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {
namespace {

// { "command": NAME } followed by the command's own keys.
nlohmann::json with_command(const std::string& name, const nlohmann::json& keys) {
  nlohmann::json j = json_summary(name);
  j.update(keys);
  return j;
}

struct OpticsArgs {
  std::string setup;
  double f_number = 0, magnification = 0, noise = 0, threshold = 0;
  std::string chi, liquid = "kerosene", led, diameters;
  std::string png;
  JsonOutput json;
  bool overwrite = false;
  CLI::Option *f_opt = nullptr, *m_opt = nullptr, *noise_opt = nullptr, *threshold_opt = nullptr, *chi_opt = nullptr,
              *liquid_opt = nullptr, *led_opt = nullptr;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = s.find(sep, start);
    out.push_back(s.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return out;
    start = end + 1;
  }
}

double number(const std::string& text, const std::string& flag) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw bad_input(fmt::format("{}: '{}' is not a number", flag, text));
}

// "Z:CHI,Z:CHI,..." or a single "CHI" (at z = 0).
std::vector<optics::ChiSample> parse_chi(const std::string& text) {
  std::vector<optics::ChiSample> out;
  for (const std::string& item : split(text, ',')) {
    const std::vector<std::string> parts = split(item, ':');
    if (parts.size() == 1) out.push_back({0.0, number(parts[0], "--chi")});
    else if (parts.size() == 2) out.push_back({number(parts[0], "--chi"), number(parts[1], "--chi")});
    else throw bad_input(fmt::format("--chi: '{}' is not Z_MM:CHI_UM (e.g. --chi -4.5:62,0:40,4.5:60)", item));
  }
  return out;
}

optics::LedSpectrum parse_led(const std::string& text) {
  const std::vector<std::string> parts = split(text, ':');
  if (parts.size() != 2) throw bad_input(fmt::format("--led '{}' is not PEAK_NM:FWHM_NM (e.g. 514:37; 0 FWHM: one line)", text));
  optics::LedSpectrum s;
  s.peak_nm = number(parts[0], "--led");
  s.fwhm_nm = number(parts[1], "--led");
  s.validate();
  return s;
}

// The set-up from --setup, or one camera from the explicit flags; --liquid and --led override.
optics::VisibilitySetup setup_from(const OpticsArgs& a, bool need_chi) {
  const bool explicit_camera = a.f_opt->count() || a.m_opt->count() || a.noise_opt->count() ||
                               a.threshold_opt->count() || a.chi_opt->count();
  optics::VisibilitySetup s;
  if (!a.setup.empty()) {
    if (explicit_camera)
      throw bad_input("--setup describes the cameras: give either --setup or --f-number/--magnification/--chi/--noise");
    s = optics::read_optics_setup(a.setup);
  } else {
    if (!a.f_opt->count() || !a.m_opt->count())
      throw bad_input("give --setup FILE, or --f-number and --magnification (with --chi and --noise for visibility)");
    optics::CameraOptics c;
    c.id = "camera";
    c.f_number = a.f_number;
    c.magnification = a.magnification;
    if (a.noise_opt->count() && a.threshold_opt->count()) throw bad_input("give --noise or --threshold, not both");
    c.noise_sigma = a.threshold_opt->count() ? 0.5 * (1.0 - a.threshold) : (a.noise_opt->count() ? a.noise : 0.01);
    if (need_chi && !a.chi_opt->count())
      throw bad_input("--chi is required: the PSF half-width in um, e.g. --chi 40 or --chi -4.5:62,0:40,4.5:60");
    c.chi = a.chi_opt->count() ? parse_chi(a.chi) : std::vector<optics::ChiSample>{{0.0, 1.0}};
    s.cameras.push_back(c);
  }
  if (a.liquid_opt->count()) s.liquid = optics::Liquid::named(a.liquid);
  if (a.led_opt->count()) s.spectrum = parse_led(a.led);
  s.validate();
  return s;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json setup_json(const optics::VisibilitySetup& s) {
  nlohmann::json cams = nlohmann::json::array();
  for (const optics::CameraOptics& c : s.cameras)
    cams.push_back({{"id", c.id},
                    {"f_number", c.f_number},
                    {"magnification", c.magnification},
                    {"numerical_aperture", optics::object_numerical_aperture(c.f_number, c.magnification)},
                    {"noise", c.noise_sigma},
                    {"threshold", c.threshold()}});
  return {{"liquid", s.liquid.name},
          {"led", {{"peak_nm", s.spectrum.peak_nm}, {"fwhm_nm", s.spectrum.fwhm_nm}}},
          {"cameras", cams}};
}

std::string cell(double v) {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return "none";
  return fmt::format("{:.1f}", v);
}

void run_visibility(const OpticsArgs& a) {
  if (!a.png.empty()) storage::check_output_path(a.png, a.overwrite, "plot");
  const optics::VisibilitySetup s = setup_from(a, true);
  const std::vector<optics::VisibilityRow> rows = optics::visibility_table(s);
  if (!a.png.empty()) storage::write_png(a.png, optics::visibility_plot(s, rows));
  if (a.json.wanted()) {
    nlohmann::json j = setup_json(s);
    j["d_max_um"] = s.d_max_um;
    nlohmann::json out_rows = nlohmann::json::array();
    for (const optics::VisibilityRow& r : rows) {
      nlohmann::json chi = nlohmann::json::array(), d = nlohmann::json::array();
      for (double v : r.chi_um) chi.push_back(finite_or_null(v));
      for (double v : r.d_min_um) d.push_back(finite_or_null(v));
      out_rows.push_back({{"z_mm", r.z_mm}, {"chi_um", chi}, {"d_min_um", d}, {"setup_d_min_um", finite_or_null(r.setup_d_min_um)}});
    }
    j["rows"] = out_rows;
    if (!a.png.empty()) j["png"] = a.png;
    emit_json(a.json, with_command("optics visibility", j));
    if (a.json.to_stdout()) return;
  }
  fmt::print("smallest visible droplet [um], {} in LED light {:g} nm ({:g} nm FWHM); threshold 1 - 2 sigma\n",
             s.liquid.name, s.spectrum.peak_nm, s.spectrum.fwhm_nm);
  for (const optics::CameraOptics& c : s.cameras)
    fmt::print("  {}: f/{:g}, M {:g}, NA {:.4f}, threshold {:.3f}\n", c.id, c.f_number, c.magnification,
               optics::object_numerical_aperture(c.f_number, c.magnification), c.threshold());
  std::string header = fmt::format("{:>8}", "z [mm]");
  for (const optics::CameraOptics& c : s.cameras) header += fmt::format(" | {:>8} {:>7}", c.id + " chi", "d_min");
  fmt::print("{} | {:>7}\n", header, "set-up");
  for (const optics::VisibilityRow& r : rows) {
    std::string line = fmt::format("{:>8.2f}", r.z_mm);
    for (std::size_t c = 0; c < r.chi_um.size(); ++c) line += fmt::format(" | {:>8} {:>7}", cell(r.chi_um[c]), cell(r.d_min_um[c]));
    fmt::print("{} | {:>7}\n", line, cell(r.setup_d_min_um));
  }
  if (!a.png.empty()) fmt::print("wrote {}\n", a.png);
}

void run_transmission(const OpticsArgs& a) {
  const optics::VisibilitySetup s = setup_from(a, false);
  if (a.diameters.empty()) throw bad_input("--d is required: droplet diameters in um, e.g. --d 5,10,20,50");
  std::vector<double> ds;
  for (const std::string& t : split(a.diameters, ',')) ds.push_back(number(t, "--d"));
  const optics::TransmissionModel model(s.liquid, s.spectrum);
  const optics::CameraOptics& c = s.cameras.front();
  const double na = optics::object_numerical_aperture(c.f_number, c.magnification);
  const bool with_chi = a.chi_opt->count() > 0 || !a.setup.empty();
  const double chi = c.chi.front().chi_um;
  nlohmann::json rows = nlohmann::json::array();
  if (!a.json.to_stdout())
    fmt::print("{} in LED light {:g} nm ({:g} nm FWHM), f/{:g}, M {:g}, NA {:.4f}{}\n{:>8} {:>8}{}\n", s.liquid.name,
               s.spectrum.peak_nm, s.spectrum.fwhm_nm, c.f_number, c.magnification, na,
               with_chi ? fmt::format(", chi {:g} um", chi) : "", "d [um]", "tau", with_chi ? fmt::format(" {:>8}", "i_min") : "");
  for (double d : ds) {
    const double tau = model.transmission(d, na);
    const double imin = with_chi ? optics::minimum_intensity(d, chi, tau) : std::nan("");
    rows.push_back({{"d_um", d}, {"tau", tau}, {"i_min", finite_or_null(imin)}});
    if (!a.json.to_stdout()) fmt::print("{:>8g} {:>8.4f}{}\n", d, tau, with_chi ? fmt::format(" {:>8.4f}", imin) : "");
  }
  if (a.json.wanted()) {
    nlohmann::json j = setup_json(s);
    j["chi_um"] = with_chi ? nlohmann::json(chi) : nlohmann::json(nullptr);
    j["rows"] = rows;
    emit_json(a.json, with_command("optics transmission", j));
  }
}

struct PsfArgs {
  std::string session, z, magnification;
  std::string method = "voxel", calib, grid, axis = "y";
  std::string png, psf_out;
  std::string setup_out, noise, liquid = "kerosene";
  double f_number = 0;
  JsonOutput json;
  bool overwrite = false;
};

// One camera's results over the session's depths (NaN: not measured).
struct PsfColumn {
  std::vector<double> chi_um, chi_voxel_um, sigma_px, object_pixel_um;
  std::vector<int> edges;
  explicit PsfColumn(std::size_t depths)
      : chi_um(depths, std::nan("")), chi_voxel_um(depths, std::nan("")), sigma_px(depths, std::nan("")),
        object_pixel_um(depths, std::nan("")), edges(depths, 0) {}
};

// Object-space size (um) of one pixel of camera c at depth z for the in-image method: from the
// session's truth camera (pinhole: depth along the axis / fx) when there is one, else pixel
// pitch / magnification.
double object_pixel_um(const storage::SessionReader& reader, const std::vector<double>& magnification, std::size_t c,
                       double z_mm) {
  if (!magnification.empty()) return reader.info().cameras[c].pixel_pitch_um / magnification[c];
  const storage::SessionTruth truth = reader.truth();
  const storage::TruthCamera& t = truth.cameras.at(c);
  const double depth = t.R[8] * z_mm + t.t.z;  // (R p + t).z for p = (0, 0, z); R row-major
  return depth / t.K[0] * 1000.0;
}

// The object pixel at the depth nearest z = 0 (for the set-up file's magnification).
double object_pixel_near_focus(const std::vector<double>& z, const PsfColumn& col) {
  double best = std::nan(""), dz = 1e300;
  for (std::size_t k = 0; k < z.size(); ++k)
    if (std::isfinite(col.object_pixel_um[k]) && std::abs(z[k]) < dz) {
      dz = std::abs(z[k]);
      best = col.object_pixel_um[k];
    }
  return best;
}

// The measured chi as a set-up file for `tomorig optics visibility --setup` (docs/spray.md).
std::string setup_toml(const PsfArgs& a, const storage::SessionReader& reader, const std::vector<double>& z,
                       const std::vector<PsfColumn>& cols) {
  const std::size_t cams = cols.size();
  std::vector<double> noise;
  for (const std::string& t : split(a.noise, ',')) noise.push_back(number(t, "--noise"));
  if (noise.size() == 1) noise.assign(cams, noise[0]);
  if (noise.size() != cams) throw bad_input(fmt::format("--noise: give one value, or one per camera ({})", cams));
  std::string t = fmt::format("# PSF half-widths measured by `tomorig optics psf` on {}.\nliquid = \"{}\"\n", a.session,
                              optics::Liquid::named(a.liquid).name);
  for (std::size_t c = 0; c < cams; ++c) {
    std::string zs, chis;
    for (std::size_t k = 0; k < z.size(); ++k) {
      if (!std::isfinite(cols[c].chi_um[k])) continue;  // a depth without a measurable edge
      zs += (zs.empty() ? "" : ", ") + fmt::format("{}", z[k]);
      chis += (chis.empty() ? "" : ", ") + fmt::format("{:.2f}", cols[c].chi_um[k]);
    }
    if (zs.empty()) throw runtime_error(fmt::format("camera '{}': no depth was measured", reader.info().cameras[c].id));
    const double m = reader.info().cameras[c].pixel_pitch_um / object_pixel_near_focus(z, cols[c]);
    t += fmt::format("\n[[cameras]]\nid = \"{}\"\nf_number = {}\nmagnification = {:.4f}\nnoise = {}\nz_mm = [{}]\nchi_um = [{}]\n",
                     reader.info().cameras[c].id, a.f_number, m, noise[c], zs, chis);
  }
  return t;
}

// The PSF file the reconstruction reads (`reconstruct --psf`), measured depths only.
optics::PsfTable psf_table(const storage::SessionReader& reader, const optics::VoxelPlane& plane, const std::string& axis,
                           const std::vector<double>& z, const std::vector<PsfColumn>& cols) {
  optics::PsfTable t;
  t.voxel_mm = plane.voxel_mm;
  t.axis = axis;
  for (std::size_t c = 0; c < cols.size(); ++c) {
    optics::PsfTableCamera cam;
    cam.id = reader.info().cameras[c].id;
    for (std::size_t k = 0; k < z.size(); ++k) {
      if (!std::isfinite(cols[c].chi_um[k])) continue;
      cam.z_mm.push_back(z[k]);
      cam.chi_um.push_back(cols[c].chi_um[k]);
      cam.chi_voxel_um.push_back(cols[c].chi_voxel_um[k]);
      cam.sigma_px.push_back(cols[c].sigma_px[k]);
    }
    if (cam.z_mm.empty()) throw runtime_error(fmt::format("camera '{}': no depth was measured", cam.id));
    t.cameras.push_back(std::move(cam));
  }
  t.validate();
  return t;
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw runtime_error(fmt::format("writing '{}' failed (is the disk full?)", path));
}

// The depth of each set: --z, else the session truth's planes[].z_mm.
std::vector<double> set_depths(const PsfArgs& a, const storage::SessionReader& reader) {
  std::vector<double> z;
  if (!a.z.empty()) {
    for (const std::string& t : split(a.z, ',')) z.push_back(number(t, "--z"));
  } else if (reader.has_truth()) {
    const nlohmann::json p = nlohmann::json::parse(reader.truth().flow_parameters, nullptr, false);
    if (p.is_object() && p.contains("planes"))
      for (const auto& plane : p["planes"])
        if (plane.contains("z_mm")) z.push_back(plane["z_mm"].get<double>());
  }
  if (z.size() != reader.set_count())
    throw bad_input(fmt::format("--z: give one depth (mm) per set of '{}' ({} sets, {} depths given)", a.session,
                                reader.set_count(), z.size()));
  return z;
}

// Thesis Sect. 6.4: each image back-projected onto the voxel plane of its depth and measured.
std::vector<PsfColumn> measure_in_voxel_planes(const PsfArgs& a, const storage::SessionReader& reader,
                                               const std::vector<double>& z, optics::VoxelPlane& plane) {
  const pipeline::SessionDescription description = pipeline::describe_session(reader);
  const pipeline::SessionCameras cameras = pipeline::session_cameras(description, a.calib);
  for (const std::string& w : cameras.warnings) fmt::print(stderr, "warning: {}\n", w);
  const std::vector<const calibration::CameraModel*> models = cameras.pointers();
  if (!a.grid.empty()) {
    const VoxelGrid g = pipeline::parse_grid(a.grid);
    plane = {g.origin.x, g.origin.y, 0.0, g.voxel_size, g.nx, g.ny};
  } else {
    std::vector<optics::ImageSize> sizes;
    for (const storage::SessionCamera& c : reader.info().cameras) sizes.push_back({c.width, c.height});
    plane = optics::common_view_plane(models, sizes, z);
  }
  plane.validate();
  const optics::SpreadAxis axis = a.axis == "x" ? optics::SpreadAxis::x : optics::SpreadAxis::y;
  std::vector<PsfColumn> cols(models.size(), PsfColumn(z.size()));
  for (std::size_t k = 0; k < z.size(); ++k) {
    const FrameSet set = reader.read_set(k);
    for (std::size_t c = 0; c < models.size() && c < set.cameras.size(); ++c) {
      if (!set.cameras[c].a.present()) continue;
      optics::VoxelPlane at = plane;
      at.z_mm = z[k];
      try {
        const optics::VoxelPsf psf = optics::measure_voxel_psf(set.cameras[c].a.image, *models[c], at, axis);
        cols[c].chi_um[k] = psf.chi_um;
        cols[c].chi_voxel_um[k] = psf.chi_voxel_um;
        cols[c].sigma_px[k] = psf.sigma_px();
        cols[c].object_pixel_um[k] = psf.object_pixel_um;
        cols[c].edges[k] = psf.edges;
      } catch (const Error& e) {
        if (e.kind() != ErrorKind::bad_input) throw;
        fmt::print(stderr, "set {} ({} mm), camera '{}': {}\n", k, z[k], reader.info().cameras[c].id, e.what());
      }
    }
  }
  return cols;
}

// The in-image variant: slanted edges measured in the camera image itself (no interpolation).
std::vector<PsfColumn> measure_in_images(const PsfArgs& a, const storage::SessionReader& reader, const std::vector<double>& z) {
  const std::size_t cams = reader.info().cameras.size();
  std::vector<double> m;
  if (!a.magnification.empty()) {
    for (const std::string& t : split(a.magnification, ',')) m.push_back(number(t, "--magnification"));
    if (m.size() == 1) m.assign(cams, m[0]);
    if (m.size() != cams) throw bad_input(fmt::format("--magnification: give one value, or one per camera ({})", cams));
    for (double v : m)
      if (!(v > 0)) throw bad_input(fmt::format("--magnification {} must be > 0", v));
  } else if (!reader.has_truth() || reader.truth().cameras.size() != cams) {
    throw bad_input("--magnification is required: the session has no camera truth to convert pixels to um");
  }
  optics::EdgeSpreadOptions options;
  options.end_margin_rows = 12;  // a chessboard's edges end at corners
  std::vector<PsfColumn> cols(cams, PsfColumn(z.size()));
  for (std::size_t k = 0; k < z.size(); ++k) {
    const FrameSet set = reader.read_set(k);
    for (std::size_t c = 0; c < cams && c < set.cameras.size(); ++c) {
      if (!set.cameras[c].a.present()) continue;
      try {
        const optics::EdgePsf psf = optics::measure_edge_psf(set.cameras[c].a.image, options);
        const double pixel = object_pixel_um(reader, m, c, z[k]);
        cols[c].chi_um[k] = psf.chi_px * pixel;
        cols[c].sigma_px[k] = std::sqrt(std::max(0.25 * psf.chi_px * psf.chi_px - 1.0 / 12.0, 1e-6));
        cols[c].object_pixel_um[k] = pixel;
        cols[c].edges[k] = static_cast<int>(psf.edges.size());
      } catch (const Error& e) {
        if (e.kind() != ErrorKind::bad_input) throw;
        fmt::print(stderr, "set {} ({} mm), camera '{}': {}\n", k, z[k], reader.info().cameras[c].id, e.what());
      }
    }
  }
  return cols;
}

void run_psf(const PsfArgs& a) {
  const bool voxel = a.method == "voxel";
  if (!voxel && a.method != "image") throw bad_input(fmt::format("--method '{}': use voxel or image", a.method));
  if (a.axis != "x" && a.axis != "y") throw bad_input(fmt::format("--axis '{}': use x or y", a.axis));
  if (!voxel && (!a.psf_out.empty() || !a.png.empty() || !a.grid.empty() || !a.calib.empty()))
    throw bad_input("--psf-out, --png, --grid and --calib belong to --method voxel (the back-projected planes)");
  if (voxel && !a.magnification.empty())
    throw bad_input("--magnification belongs to --method image: in voxel planes the cameras (--calib) give the scale");
  if (!a.setup_out.empty()) {
    storage::check_output_path(a.setup_out, a.overwrite, "set-up");
    if (!(a.f_number > 0) || a.noise.empty())
      throw bad_input("--setup-out needs --f-number and --noise (sigma of the flat-fielded bright field, one or one "
                      "per camera) to describe the cameras");
  }
  if (!a.psf_out.empty()) storage::check_output_path(a.psf_out, a.overwrite, "PSF file");
  if (!a.png.empty()) storage::check_output_path(a.png, a.overwrite, "plot");
  cli::require_session(a.session, "optics psf");
  const storage::SessionReader reader(a.session);
  const std::size_t sets = reader.set_count(), cams = reader.info().cameras.size();
  if (sets == 0) throw bad_input(fmt::format("session '{}' has no sets: record one target image per depth", a.session));
  const std::vector<double> z = set_depths(a, reader);
  optics::VoxelPlane plane;
  const std::vector<PsfColumn> cols = voxel ? measure_in_voxel_planes(a, reader, z, plane) : measure_in_images(a, reader, z);
  if (std::none_of(cols.begin(), cols.end(), [](const PsfColumn& c) {
        return std::any_of(c.chi_um.begin(), c.chi_um.end(), [](double v) { return std::isfinite(v); });
      }))
    throw bad_input(fmt::format("no image of '{}' gave a PSF (the reasons are above): are they chessboard images, and is "
                                "the plane where the board is?",
                                a.session));

  // Everything is checked before anything is written.
  std::string setup_text, psf_text;
  std::optional<optics::PsfTable> table;
  if (!a.setup_out.empty()) {
    setup_text = setup_toml(a, reader, z, cols);
    optics::parse_optics_setup(setup_text, a.setup_out);  // what we write must read back
  }
  if (voxel && (!a.psf_out.empty() || !a.png.empty())) table = psf_table(reader, plane, a.axis, z, cols);
  if (!a.psf_out.empty()) {
    psf_text = optics::psf_table_toml(*table, fmt::format("PSF per camera and depth, measured by `tomorig optics psf` on {}\n"
                                                          "from chessboard edges in voxel planes (docs/spray.md).",
                                                          a.session));
    optics::parse_psf_table(psf_text, a.psf_out);
  }
  if (!a.setup_out.empty()) write_text_file(a.setup_out, setup_text);
  if (!a.psf_out.empty()) write_text_file(a.psf_out, psf_text);
  if (!a.png.empty()) storage::write_png(a.png, optics::psf_plot(*table));

  if (a.json.wanted()) {
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t c = 0; c < cams; ++c) {
      nlohmann::json chi = nlohmann::json::array(), chi_voxel = nlohmann::json::array(), sigma = nlohmann::json::array();
      for (std::size_t k = 0; k < sets; ++k) {
        chi.push_back(finite_or_null(cols[c].chi_um[k]));
        chi_voxel.push_back(finite_or_null(cols[c].chi_voxel_um[k]));
        sigma.push_back(finite_or_null(cols[c].sigma_px[k]));
      }
      nlohmann::json cam = {{"id", reader.info().cameras[c].id}, {"z_mm", z},      {"chi_um", chi},
                            {"sigma_px", sigma},                 {"edges", cols[c].edges}};
      if (voxel) cam["chi_voxel_um"] = chi_voxel;
      out.push_back(cam);
    }
    nlohmann::json j{{"session", a.session}, {"method", a.method}, {"cameras", out}};
    if (voxel)
      j["plane"] = {{"x0_mm", plane.x0_mm}, {"y0_mm", plane.y0_mm}, {"voxel_mm", plane.voxel_mm},
                    {"nx", plane.nx},       {"ny", plane.ny},       {"axis", a.axis}};
    if (!a.psf_out.empty()) j["psf_out"] = a.psf_out;
    if (!a.png.empty()) j["png"] = a.png;
    if (!a.setup_out.empty()) j["setup_out"] = a.setup_out;
    emit_json(a.json, with_command("optics psf", j));
    if (a.json.to_stdout()) return;
  }
  if (voxel)
    fmt::print("PSF half-width chi [um] from chessboard edges back-projected onto voxel planes ({} x {} voxels of {:.4f} "
               "mm, spread along {}): the camera's PSF (in the voxel plane)\n",
               plane.nx, plane.ny, plane.voxel_mm, a.axis);
  else
    fmt::print("PSF half-width chi [um] from edges in the camera images (knife-edge, Gaussian fit of the line spread)\n");
  fmt::print("{:>8}", "z [mm]");
  for (std::size_t c = 0; c < cams; ++c) fmt::print(" {:>16}", reader.info().cameras[c].id);
  fmt::print("\n");
  for (std::size_t k = 0; k < sets; ++k) {
    fmt::print("{:>8.2f}", z[k]);
    for (std::size_t c = 0; c < cams; ++c)
      fmt::print(" {:>16}", voxel && std::isfinite(cols[c].chi_um[k])
                                ? fmt::format("{} ({})", cell(cols[c].chi_um[k]), cell(cols[c].chi_voxel_um[k]))
                                : cell(cols[c].chi_um[k]));
    fmt::print("\n");
  }
  for (const std::string* f : {&a.psf_out, &a.setup_out, &a.png})
    if (!f->empty()) fmt::print("wrote {}\n", *f);
}

void add_common(CLI::App* cmd, OpticsArgs& a) {
  cmd->add_option("--setup", a.setup, "optics set-up file (TOML, docs/spray.md): liquid, LED, cameras with chi(z)");
  a.f_opt = cmd->add_option("--f-number", a.f_number, "lens f-number (one camera, instead of --setup)");
  a.m_opt = cmd->add_option("--magnification", a.magnification, "magnification M");
  a.chi_opt = cmd->add_option("--chi", a.chi, "PSF half-width in um: CHI, or Z_MM:CHI_UM,... over depth");
  a.noise_opt = cmd->add_option("--noise", a.noise, "sigma of the flat-fielded bright field (default 0.01)");
  a.threshold_opt = cmd->add_option("--threshold", a.threshold, "threshold of visibility instead of --noise (1 - 2 sigma)");
  a.liquid_opt = cmd->add_option("--liquid", a.liquid, "water or kerosene (default kerosene, or the set-up's)");
  a.led_opt = cmd->add_option("--led", a.led, "LED spectrum PEAK_NM:FWHM_NM (default 514:37)");
  add_json_flag(*cmd, a.json);
}

}  // namespace

void add_optics_command(CLI::App& root) {
  CLI::App* optics_cmd = root.add_subcommand("optics", "Droplet imaging model of tomographic shadowgraphy: transmission, "
                                                       "smallest visible droplet");
  optics_cmd->require_subcommand(1);

  auto vis = std::make_shared<OpticsArgs>();
  CLI::App* v = optics_cmd->add_subcommand("visibility", "Smallest visible droplet per camera and depth, and for the "
                                                         "set-up (thesis Sect. 6.4, 7.3.3)");
  add_common(v, *vis);
  v->add_option("--png", vis->png, "write the plot (Fig. 7.10 style) to this PNG");
  v->add_flag("--overwrite", vis->overwrite, "replace an existing --png file");
  v->callback([vis] { run_visibility(*vis); });

  auto tr = std::make_shared<OpticsArgs>();
  CLI::App* t = optics_cmd->add_subcommand("transmission", "Droplet transmission tau (Mie, Sect. 6.1) and, with --chi, "
                                                           "the shadow's minimum intensity (Eq. 6.6)");
  add_common(t, *tr);
  t->add_option("--d", tr->diameters, "droplet diameters in um, comma-separated");
  t->callback([tr] { run_transmission(*tr); });

  auto psf = std::make_shared<PsfArgs>();
  CLI::App* p = optics_cmd->add_subcommand("psf", "PSF half-width chi per camera and depth from chessboard calibration "
                                                  "images (knife-edge technique in voxel planes, Sect. 6.4)");
  cli::add_session_argument(*p, psf->session, "session with one set per depth, each camera's target image in exposure A");
  p->add_option("--z", psf->z, "depth of each set in mm, comma-separated (default: the session truth's planes)");
  p->add_option("--method", psf->method, "voxel: back-project onto voxel planes (thesis); image: edges in the camera "
                                         "images")
      ->capture_default_str();
  p->add_option("--calib", psf->calib, "cameras for the back-projection: a calibration file (tomorig calibrate) or "
                                       "'truth' (default: the truth if present, else the rig config's calibration)");
  p->add_option("--grid", psf->grid, "the voxel planes: nx,ny,nz,voxel_mm[,cx,cy,cz] (nz and cz unused; default: the "
                                     "square every camera sees at every depth, ~1 voxel per pixel)");
  p->add_option("--axis", psf->axis, "direction of the measured spread in the plane: x or y")->capture_default_str();
  p->add_option("--magnification", psf->magnification,
                "--method image: magnification, one or one per camera (default: from the session's truth cameras)");
  add_json_flag(*p, psf->json);
  p->add_option("--png", psf->png, "write the plot of chi over depth (Fig. 6.15 / 7.9 style) to this PNG");
  p->add_option("--psf-out", psf->psf_out, "write the PSF file (TOML) that `reconstruct --psf` / `process --psf` read");
  p->add_option("--setup-out", psf->setup_out, "also write the result as an optics set-up file (TOML) for "
                                               "`optics visibility --setup`");
  p->add_option("--f-number", psf->f_number, "--setup-out: the lenses' f-number");
  p->add_option("--noise", psf->noise, "--setup-out: sigma of the flat-fielded bright field, one or one per camera");
  p->add_option("--liquid", psf->liquid, "--setup-out: water or kerosene")->capture_default_str();
  p->add_flag("--overwrite", psf->overwrite, "replace existing --setup-out, --psf-out or --png files");
  p->callback([psf] { run_psf(*psf); });
}

}  // namespace tomorig::app
