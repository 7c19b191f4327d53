// tomorig calibrate: fits camera models to point correspondences, either made elsewhere
// (--points POINTS.csv) or detected here in target images (--images DIR, --image-list CSV or
// --session S.h5, with a target spec), optionally corrects traverse errors of the target
// planes (--stage-correction, thesis Sect. 6.3.3), writes the calibration file and prints the residual report of thesis
// Tables 5.3 and 6.4 (per camera and model, and per plane: forward residual in px, reverse
// residual in um).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "tomorig/pipeline/target_images.h"
#include "calibrate_report.h"
#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/pipeline/correspondence_csv.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/calibrate_cameras.h"
#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/target_depths.h"
#include "tomorig/processing/calibration/target_file.h"
#include "tomorig/processing/calibration/residual_plot.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/output_path.h"

namespace tomorig::app {

using pipeline::CorrespondenceTable;
using pipeline::DetectedTargets;
using pipeline::TargetImage;
using pipeline::TargetImageSet;
using pipeline::detect_targets;
using pipeline::find_target_images;
using pipeline::orient_y_axis;
using pipeline::read_correspondence_csv;
using pipeline::read_image_list;
using pipeline::read_session_targets;
using pipeline::write_correspondence_csv;

namespace {

struct CalibrateArgs {
  std::string points;
  std::string images;
  std::string image_list;
  std::string session;
  std::string z_list;
  bool stage_correction = false;
  std::string points_out;
  std::string overlay;  // --overlay DIR: a PNG per target image showing what was detected
  std::string png;      // --png DIR: the stored model's residuals per camera and plane
  // Target spec (with --images / --image-list).
  std::string target = "dots";
  double spacing_mm = 0;
  std::string dots = "white";
  std::string y_axis = "auto";
  std::string corners;
  double max_feature_px = 0;
  std::string lattice = "square";
  double level_offset_mm = 0;
  std::string target_file;                  // --target-file T.toml: the target spec from a file
  std::string target_z;                     // --target-z Z.csv: each target point's z from a side file
  std::vector<std::string> target_options;  // the target options given on the command line
  int min_points_per_plane = 8;
  std::string models = "pinhole";
  std::string store;  // empty: the last of --models
  std::string image_size;
  std::vector<std::string> camera_sizes;
  int max_iterations = calibration::FitOptions{}.max_iterations;
  // The refractive model's window (--window-*): thickness, indices, approximate pose.
  double window_thickness_mm = -1;  // < 0: no window given
  std::string indices = "1.0,1.49,1.33";
  double window_face_mm = 0;
  std::string window_normal = "0,0,1";
  bool fix_window = false;
  bool fit_medium_index = false;
  std::string out;
  std::string check;  // --check CALIB: evaluate a calibration on --points instead of fitting
  bool overwrite = false;
  JsonOutput json;
  std::string cross_validate;  // "", "planes" (leave one plane out) or "points" (one point), per camera and model
};

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  for (;;) {
    const auto comma = text.find(',', start);
    items.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return items;
    start = comma + 1;
  }
}

// "--models pinhole,rational2": known names, no repeats.
std::vector<std::string> parse_models(const std::string& text) {
  const auto& known = calibration::all_camera_model_names();
  const std::vector<std::string> models = split_list(text);
  for (std::size_t k = 0; k < models.size(); ++k) {
    if (std::find(known.begin(), known.end(), models[k]) == known.end())
      throw bad_input(fmt::format("--models '{}': unknown camera model '{}'; known models: {}", text, models[k],
                                  fmt::join(known, ", ")));
    if (std::find(models.begin(), models.begin() + static_cast<std::ptrdiff_t>(k), models[k]) !=
        models.begin() + static_cast<std::ptrdiff_t>(k))
      throw bad_input(fmt::format("--models '{}': model '{}' is listed twice", text, models[k]));
  }
  return models;
}

bool parse_int(std::string_view text, int& value) {
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return !text.empty() && ec == std::errc() && ptr == text.data() + text.size();
}

// "W,H" with W, H > 0.
calibration::ImageSize parse_size(const std::string& text, const std::string& option) {
  const auto parts = split_list(text);
  calibration::ImageSize size;
  if (parts.size() != 2 || !parse_int(parts[0], size.width) || !parse_int(parts[1], size.height) || size.width <= 0 ||
      size.height <= 0)
    throw bad_input(fmt::format("{} '{}' is not valid: expected W,H in pixels, both > 0, e.g. 1600,1200", option, text));
  return size;
}

// Image size of each camera: --camera-size i=W,H overrides --image-size W,H; every camera needs one,
// because the calibration file records it and reconstruct checks it against the images.
std::vector<calibration::ImageSize> image_sizes(const CalibrateArgs& args, std::size_t camera_count) {
  std::map<int, calibration::ImageSize> per_camera;
  for (const std::string& entry : args.camera_sizes) {
    const auto eq = entry.find('=');
    int camera = -1;
    if (eq == std::string::npos || !parse_int(std::string_view(entry).substr(0, eq), camera) || camera < 0)
      throw bad_input(fmt::format("--camera-size '{}' is not valid: expected i=W,H, e.g. 0=1600,1200", entry));
    if (camera >= static_cast<int>(camera_count))
      throw bad_input(fmt::format("--camera-size '{}': camera {} is not in the point file, which has cameras 0 to {}",
                                  entry, camera, camera_count - 1));
    per_camera[camera] = parse_size(entry.substr(eq + 1), "--camera-size " + entry.substr(0, eq) + "=");
  }
  std::optional<calibration::ImageSize> all;
  if (!args.image_size.empty()) all = parse_size(args.image_size, "--image-size");
  std::vector<calibration::ImageSize> sizes;
  for (std::size_t i = 0; i < camera_count; ++i) {
    const auto found = per_camera.find(static_cast<int>(i));
    if (found != per_camera.end())
      sizes.push_back(found->second);
    else if (all)
      sizes.push_back(*all);
    else
      throw bad_input(fmt::format("camera {}: no image size; give --image-size W,H for all cameras or "
                                  "--camera-size {}=W,H (the calibration file records it)",
                                  i, i));
  }
  return sizes;
}

// The target spec from --target-file or the command line; `y_axis` is set to the image
// direction of world +y asked for (auto, down or up).
calibration::TargetSpec target_spec(const CalibrateArgs& args, std::string& y_axis) {
  y_axis = args.y_axis;
  if (!args.target_file.empty()) {
    if (!args.target_options.empty())
      throw bad_input(fmt::format("--target-file {} describes the target; {} do(es) not go with it: put the value in "
                                  "the file",
                                  args.target_file, fmt::join(args.target_options, ", ")));
    calibration::TargetFile file = calibration::read_target_file(args.target_file);
    y_axis = file.y_axis;
    return file.spec;
  }
  if (!(args.spacing_mm > 0))
    throw bad_input(fmt::format("--spacing {} is invalid: give the target's dot spacing or chessboard square size in mm "
                                "(> 0), e.g. --spacing 3",
                                args.spacing_mm));
  if (args.target == "dots") {
    calibration::DotGridSpec spec;
    spec.spacing_mm = args.spacing_mm;
    if (args.dots != "white" && args.dots != "black")
      throw bad_input(fmt::format("--dots '{}' is invalid: white (white dots on black) or black", args.dots));
    spec.white_dots = args.dots == "white";
    if (args.y_axis != "auto" && args.y_axis != "down" && args.y_axis != "up")
      throw bad_input(fmt::format("--y-axis '{}' is invalid: auto, down or up (the image direction of world +y)", args.y_axis));
    spec.y_down = args.y_axis != "up";  // auto: detected with y down, flipped afterwards if need be
    if (!(args.max_feature_px >= 0))
      throw bad_input(fmt::format("--max-feature-px {} is invalid: it must be >= 0 (0 = automatic)", args.max_feature_px));
    spec.max_feature_px = args.max_feature_px;
    if (args.lattice != "square" && args.lattice != "staggered")
      throw bad_input(fmt::format("--lattice '{}' is invalid: square or staggered (a second sub-lattice at the cell "
                                  "centres, possibly on a second depth level)",
                                  args.lattice));
    spec.lattice = args.lattice == "staggered" ? calibration::DotLattice::staggered : calibration::DotLattice::square;
    if (!std::isfinite(args.level_offset_mm) || (args.level_offset_mm != 0 && spec.lattice != calibration::DotLattice::staggered))
      throw bad_input(fmt::format("--level-offset {} needs --lattice staggered: the second level's dots sit between the "
                                  "first's",
                                  args.level_offset_mm));
    spec.level_offset_mm = args.level_offset_mm;
    return spec;
  }
  if (args.target == "chessboard") {
    calibration::ChessboardSpec spec;
    const auto parts = split_list(args.corners);
    if (parts.size() != 2 || !parse_int(parts[0], spec.inner_corners_x) || !parse_int(parts[1], spec.inner_corners_y) ||
        spec.inner_corners_x < 2 || spec.inner_corners_y < 2)
      throw bad_input(fmt::format("--corners '{}' is invalid: a chessboard target needs its inner corners NX,NY "
                                  "(both >= 2), e.g. --corners 9,6",
                                  args.corners));
    spec.square_mm = args.spacing_mm;
    return spec;
  }
  throw bad_input(fmt::format("--target '{}' is invalid: dots or chessboard", args.target));
}

// Point correspondences and image sizes, from the CSV or detected in target images.
struct Inputs {
  CorrespondenceTable table;
  std::vector<calibration::ImageSize> sizes;
  std::vector<std::string> camera_names;
};

// "--z-list -4.5,-3,..." in mm.
std::vector<double> parse_z_list(const std::string& text) {
  std::vector<double> z;
  if (text.empty()) return z;
  for (const std::string& item : split_list(text)) {
    double value = 0;
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || !std::isfinite(value))
      throw bad_input(fmt::format("--z-list '{}': '{}' is not a number of mm; give one plane z per set, e.g. "
                                  "--z-list -4.5,-3,-1.5,0,1.5,3,4.5",
                                  text, item));
    z.push_back(value);
  }
  return z;
}

// "a,b,c" -> numbers, exactly `count` of them, each finite.
std::vector<double> parse_numbers(const std::string& text, std::size_t count, const std::string& option,
                                  const std::string& example) {
  std::vector<double> out;
  for (const std::string& item : split_list(text)) {
    double value = 0;
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || !std::isfinite(value))
      throw bad_input(fmt::format("{} '{}': '{}' is not a number; expected {}", option, text, item, example));
    out.push_back(value);
  }
  if (out.size() != count)
    throw bad_input(fmt::format("{} '{}': {} values, expected {}: {}", option, text, out.size(), count, example));
  return out;
}

// The window of the refractive model from --window-thickness, --indices, --window-face and
// --window-normal; nullopt if no thickness was given.
std::optional<calibration::FlatWindow> window_of(const CalibrateArgs& args, const std::vector<std::string>& models) {
  const bool wanted = std::find(models.begin(), models.end(), "refractive") != models.end();
  if (args.window_thickness_mm < 0) {
    if (wanted)
      throw bad_input("the refractive model needs the window: give --window-thickness MM (and --indices "
                      "n_air,n_window,n_medium, --window-face MM, --window-normal X,Y,Z as they apply)");
    return std::nullopt;
  }
  if (!wanted) throw bad_input("--window-thickness goes with the refractive model; add refractive to --models");
  calibration::FlatWindow w;
  w.thickness_mm = args.window_thickness_mm;
  const auto n = parse_numbers(args.indices, 3, "--indices", "n_air,n_window,n_medium, e.g. 1.0,1.49,1.33");
  w.n_air = n[0], w.n_window = n[1], w.n_medium = n[2];
  const auto v = parse_numbers(args.window_normal, 3, "--window-normal", "X,Y,Z, e.g. 0,0,1");
  const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(length > 0)) throw bad_input("--window-normal must not be zero");
  w.normal = {v[0] / length, v[1] / length, v[2] / length};
  w.medium_face_mm = args.window_face_mm;
  if (const std::string problem = w.validate(); !problem.empty()) throw bad_input("window: " + problem);
  return w;
}

// A point outside its camera's image is a wrong point or a wrong --image-size; either would be
// stored as a calibration that does not match the images.
void check_inside_images(const std::string& file, const CorrespondenceTable& table,
                         const std::vector<calibration::ImageSize>& sizes) {
  for (std::size_t c = 0; c < table.cameras.size(); ++c)
    for (std::size_t k = 0; k < table.cameras[c].size(); ++k) {
      const Vec2d& p = table.cameras[c][k].pixel;
      const calibration::ImageSize s = sizes[c];
      // Pixel centres at integers: an image of width W spans [-0.5, W - 0.5].
      if (p.x >= -0.5 && p.x <= s.width - 0.5 && p.y >= -0.5 && p.y <= s.height - 0.5) continue;
      const std::string line = c < table.lines.size() && k < table.lines[c].size() ? fmt::format(":{}", table.lines[c][k]) : "";
      throw bad_input(fmt::format("{}{}: camera {}: the image point ({}, {}) px lies outside the camera's {} x {} px image "
                                  "(pixels span -0.5 to W-0.5); check the point, or give the true size with "
                                  "--image-size W,H or --camera-size {}=W,H",
                                  file, line, c, p.x, p.y, s.width, s.height, c));
    }
}

Inputs read_inputs(const CalibrateArgs& args) {
  const int sources = !args.points.empty() + !args.images.empty() + !args.image_list.empty() + !args.session.empty();
  if (sources != 1)
    throw bad_input("give exactly one of --points CSV (correspondences made elsewhere), --images DIR, --image-list CSV "
                    "or --session S.h5 (target images)");
  if (!args.z_list.empty() && args.session.empty())
    throw bad_input("--z-list gives the plane z of each set of a --session; it does not go with other sources");
  Inputs in;
  if (!args.points.empty()) {
    if (!args.target_file.empty())
      throw bad_input("--target-file describes the target in target images; it does not go with --points");
    if (!args.target_z.empty())
      throw bad_input("--target-z gives the z of the points detected in target images; with --points the Z column "
                      "of the point file is each point's z");
    in.table = read_correspondence_csv(args.points);
    in.sizes = image_sizes(args, in.table.cameras.size());
    check_inside_images(args.points, in.table, in.sizes);
    for (std::size_t c = 0; c < in.table.cameras.size(); ++c) in.camera_names.push_back(fmt::format("camera {}", c));
    return in;
  }
  if (!args.image_size.empty() || !args.camera_sizes.empty())
    throw bad_input("--image-size and --camera-size go with --points only; with target images the size is the images'");
  if (args.min_points_per_plane < 1)
    throw bad_input(fmt::format("--min-points-per-plane {} is invalid: it must be >= 1", args.min_points_per_plane));
  std::string y_axis;
  const calibration::TargetSpec spec = target_spec(args, y_axis);
  // Read before the detection, so that a malformed file costs nothing.
  std::optional<calibration::TargetDepths> depths;
  if (!args.target_z.empty()) {
    if (const auto* dots = std::get_if<calibration::DotGridSpec>(&spec); dots && (dots->level_offset_mm != 0 || dots->origin_mm.z != 0))
      throw bad_input(fmt::format("--target-z {} gives each point's z relative to the plate; a level offset (--level-offset "
                                  "or level_offset_mm) or an origin z (origin_mm) does not go with it: put those depths "
                                  "into the file",
                                  args.target_z));
    depths = calibration::read_target_depths(args.target_z);
  }
  const TargetImageSet set = !args.session.empty()  ? read_session_targets(args.session, parse_z_list(args.z_list))
                             : !args.images.empty() ? find_target_images(args.images)
                                                    : read_image_list(args.image_list);
  DetectedTargets detected = detect_targets(set, spec, args.min_points_per_plane, {args.overlay, args.overwrite});
  for (const std::string& warning : detected.warnings) fmt::print(stderr, "warning: {}\n", warning);
  for (const std::string& origin : detected.origins) fmt::print(stderr, "{}\n", origin);
  if (std::holds_alternative<calibration::DotGridSpec>(spec) && y_axis == "auto")
    fmt::print(stderr, "world +y points {} the images (--y-axis auto: a right-handed x, y, z)\n", orient_y_axis(detected));
  if (depths) {
    calibration::apply_target_depths(detected.table.cameras, *depths);
    fmt::print(stderr, "point z from --target-z {} ({} points listed)\n", args.target_z, depths->z_mm.size());
  }
  for (std::size_t c = 0; c < set.camera_names.size(); ++c)
    fmt::print(stderr, "camera {} ({}): {} target points on {} images of {} x {} px\n", c, set.camera_names[c],
               detected.table.cameras[c].size(),
               std::count_if(set.images.begin(), set.images.end(), [&](const TargetImage& i) { return i.camera == static_cast<int>(c); }),
               detected.image_sizes[c].width, detected.image_sizes[c].height);
  if (!args.points_out.empty()) write_correspondence_csv(args.points_out, detected.table);
  in.table = std::move(detected.table);
  in.sizes = std::move(detected.image_sizes);
  in.camera_names = set.camera_names;
  return in;
}

// --check CALIB --points PTS: the calibration's error on points (normally not used in its
// fit), per camera, in the residual table's terms.
void run_check(const CalibrateArgs& args) {
  if (args.points.empty())
    throw bad_input("--check CALIB needs --points PTS: the point correspondences to evaluate the calibration on");
  if (!args.out.empty()) throw bad_input("--check evaluates a calibration; it writes nothing, so -o does not go with it");
  const auto calibrations = calibration::load_calibration(args.check);
  const CorrespondenceTable table = read_correspondence_csv(args.points);
  std::vector<ModelResult> results;
  for (std::size_t i = 0; i < table.cameras.size(); ++i) {
    const auto found = std::find_if(calibrations.begin(), calibrations.end(),
                                    [&](const calibration::CameraCalibration& c) { return c.id == static_cast<int>(i); });
    if (found == calibrations.end())
      throw bad_input(fmt::format("{}: camera {} has points, but {} has no camera with id {}", args.points, i, args.check, i));
    calibration::FitReport report = found->report;
    calibration::measure_residuals(*found->model, table.cameras[i], report);
    report.camera = fmt::format("camera {}", i);
    report.retry.clear();
    results.push_back({static_cast<int>(i), report, calibration::plane_residuals(*found->model, table.cameras[i])});
  }
  if (args.json.wanted()) {
    nlohmann::json j = json_summary("calibrate");
    j.update(nlohmann::json{{"check", args.check}, {"points", args.points}, {"results", report_json(results)}});
    emit_json(args.json, j);
    if (args.json.to_stdout()) return;
  }
  fmt::print("{} on the points of {} (not fitted: the residuals are its error there)\n", args.check, args.points);
  print_report(results, "", "");
}

// --png DIR: one picture per camera and plane, "cam<i>_z<z>mm_residuals.png". The names are
// made once, before any fit, where each is checked (no picture is replaced without
// --overwrite); the same list is written after the fit.
struct ResidualPlotFiles {
  std::filesystem::path dir;                                      // empty: no --png
  std::map<std::pair<int, double>, std::filesystem::path> files;  // (camera, plane z) -> picture
};

ResidualPlotFiles prepare_residual_plots(const std::string& dir,
                                         const std::vector<std::vector<calibration::PointCorrespondence>>& cameras,
                                         bool overwrite) {
  ResidualPlotFiles plots{dir, {}};
  if (dir.empty()) return plots;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  for (std::size_t c = 0; c < cameras.size(); ++c)
    for (const auto& p : cameras[c])
      plots.files.try_emplace({static_cast<int>(c), p.world.z},
                        std::filesystem::path(dir) / fmt::format("cam{}_z{:g}mm_residuals.png", c, p.world.z));
  for (const auto& [key, file] : plots.files) storage::check_output_path(file.string(), overwrite, "residual plot");
  return plots;
}

void write_residual_plots(const ResidualPlotFiles& plots,
                          const std::vector<std::vector<calibration::PointCorrespondence>>& cameras,
                          const std::vector<calibration::CameraCalibration>& calibrations) {
  if (plots.dir.empty()) return;
  for (const auto& [key, file] : plots.files) {
    const auto& [camera, z] = key;
    const auto stored = std::find_if(calibrations.begin(), calibrations.end(),
                                     [camera = camera](const auto& c) { return c.id == camera; });
    if (stored == calibrations.end()) continue;
    std::vector<calibration::PointCorrespondence> plane;
    for (const auto& p : cameras[static_cast<std::size_t>(camera)])
      if (p.world.z == z) plane.push_back(p);
    const calibration::ResidualPlot plot = calibration::residual_plot(
        *stored->model, plane, stored->image_size, fmt::format("camera {}, plane z = {:g} mm, {}", camera, z, stored->report.model));
    storage::write_png(file, plot.image);
  }
  fmt::print(stderr, "residual plots in {}\n", plots.dir.string());
}

void run(const CalibrateArgs& args) {
  if (!args.check.empty()) return run_check(args);
  if (args.out.empty()) throw bad_input("-o,--out CALIB.toml is required: the calibration file to write");
  // Before any fit: an existing calibration is never replaced without --overwrite.
  storage::check_output_path(args.out, args.overwrite, "calibration");
  calibration::CalibrateCamerasOptions options;
  options.choose_model = args.models == "auto";
  options.models = options.choose_model ? calibration::camera_model_names() : parse_models(args.models);
  if (options.choose_model && args.window_thickness_mm >= 0) options.models.push_back("refractive");
  if (options.choose_model && !args.store.empty())
    throw bad_input("--models auto chooses the stored model; --store does not go with it");
  options.stored = args.store.empty() ? options.models.back() : args.store;
  if (std::find(options.models.begin(), options.models.end(), options.stored) == options.models.end())
    throw bad_input(fmt::format("--store {} is not one of --models {}; the stored model must be fitted", options.stored,
                                args.models));
  if (args.max_iterations < 1)
    throw bad_input(fmt::format("--max-iterations {} is invalid: it must be >= 1", args.max_iterations));
  if (!args.points.empty() && !args.overlay.empty())
    throw bad_input("--overlay draws what was detected in target images; it does not go with --points");
  if (!args.points.empty() && !args.points_out.empty())
    throw bad_input("--points-out writes the points detected in target images; it does not go with --points");
  options.fit.max_iterations = args.max_iterations;
  options.fit.window = window_of(args, options.models);
  options.fit.fit_window_pose = !args.fix_window;
  options.fit.fit_medium_index = args.fit_medium_index;
  options.stage_correction = args.stage_correction;
  if (!args.cross_validate.empty() && args.cross_validate != "planes" && args.cross_validate != "points")
    throw bad_input(fmt::format("--cross-validate={} is invalid: planes (leave one plane out, the default) or points "
                                "(leave one point out)",
                                args.cross_validate));
  options.cross_validate = !args.cross_validate.empty();
  options.leave_out = args.cross_validate == "points" ? calibration::LeaveOut::point : calibration::LeaveOut::plane;
  options.notice = [](const std::string& text) { fmt::print(stderr, "{}\n", text); };
  const Inputs in = read_inputs(args);
  options.camera_names = in.camera_names;
  // Before any fit: no picture is replaced without --overwrite.
  const ResidualPlotFiles residual_plots = prepare_residual_plots(args.png, in.table.cameras, args.overwrite);

  const calibration::CalibrateCamerasReport result = calibration::calibrate_cameras(in.table.cameras, in.sizes, options);
  // Nothing is written unless the stored model fitted every camera.
  if (!result.stored_failure) calibration::save_calibration(args.out, result.calibrations);
  for (const std::string& warning : result.poor_fit_warnings()) fmt::print(stderr, "warning: {}\n", warning);
  if (!result.stored_failure) write_residual_plots(residual_plots, in.table.cameras, result.calibrations);
  const std::string written = result.stored_failure ? std::string() : args.out;
  if (args.json.wanted()) {
    nlohmann::json j = json_summary("calibrate");
    j.update(nlohmann::json{{"results", report_json(result.results)}, {"stored", result.stored}});
    j["out"] = written.empty() ? nlohmann::json(nullptr) : nlohmann::json(written);
    j["stage_correction"] = result.offsets ? stage_offsets_json(*result.offsets) : nlohmann::json(nullptr);
    if (!result.validation.empty()) j["cross_validation"] = cross_validation_json(result.validation);
    emit_json(args.json, j);
  }
  if (!args.json.to_stdout()) {
    if (result.offsets) print_stage_offsets(*result.offsets);
    print_report(result.results, result.stored, written);
    if (!result.validation.empty()) print_cross_validation(result.validation);
  }
  if (result.stored_failure == ErrorKind::bad_input) throw bad_input(result.failure_message());
  if (result.stored_failure) throw runtime_error(result.failure_message());
}

}  // namespace

void add_calibrate_command(CLI::App& root) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = root.add_subcommand("calibrate", "Fit camera models to target images or point correspondences and write a calibration file");
  cmd->add_option("--points", args->points, "Point correspondences made elsewhere, CSV with the header camera,X,Y,Z,x,y (mm, px)");
  cmd->add_option("--images", args->images,
                  "Target images: a folder with one sub-folder per camera (cam0, cam1, ...) of images named "
                  "<z>mm*.tif, e.g. cam0/-3mm_cam0.tif");
  cmd->add_option("--image-list", args->image_list, "Target images: a CSV with the header camera,z,file (z in mm)");
  cli::add_session_argument(*cmd, args->session,
                            "Target images: a session file, one set per plane, exposure A of each camera (e.g. from "
                            "`tomorig simulate --case calib-thesis`); plane z from its truth or --z-list");
  cmd->add_option("--z-list", args->z_list, "With --session: the plane z of each set, mm, comma-separated in set order");
  cmd->add_flag("--stage-correction", args->stage_correction,
                "Correct traverse errors of the target planes (thesis Sect. 6.3.3) before the final fits; prints the "
                "per-plane offsets (needs >= 2 cameras and >= 2 planes)");
  cmd->add_option("--target", args->target, "Target kind: dots (dot grid with origin marker) or chessboard")
      ->capture_default_str();
  cmd->add_option("--spacing", args->spacing_mm, "Dot spacing or chessboard square size, mm");
  cmd->add_option("--dots", args->dots, "Dot polarity: white (on black) or black (on white)")->capture_default_str();
  cmd->add_option("--y-axis", args->y_axis,
                  "Image direction of world +y on a dot grid: down, up, or auto (whichever makes x, y, z right-handed, "
                  "judged from the target's image growing or shrinking with z)")
      ->capture_default_str();
  cmd->add_option("--corners", args->corners, "Chessboard inner corners NX,NY");
  cmd->add_option("--lattice", args->lattice,
                  "Dot lattice: square, or staggered (a second sub-lattice at the cell centres; --spacing is then the "
                  "row pitch, sqrt(2) times the nearest-dot spacing)")
      ->capture_default_str();
  cmd->add_option("--level-offset", args->level_offset_mm,
                  "Staggered two-level plate: z of the second level's dots relative to the origin's, mm");
  cmd->add_option("--target-file", args->target_file,
                  "Target description TOML (kind, pitch_mm, lattice, level_offset_mm, dots, y_axis, origin_mm, corners; "
                  "docs/calibration.md) instead of the target options");
  cmd->add_option("--target-z", args->target_z,
                  "Target images: each target point's z from a side file, a CSV with the header X,Y,Z (world x, y as "
                  "--points-out writes them; z relative to the plate, mm), for plates whose points lie at several depths");
  cmd->add_option("--max-feature-px", args->max_feature_px,
                  "Dot grid: dots and marker are smaller than this many pixels (0 = 1/8 of the image)")
      ->capture_default_str();
  cmd->add_option("--min-points-per-plane", args->min_points_per_plane,
                  "Fewest target points an image must yield; fewer is an error naming camera and plane")
      ->capture_default_str();
  cmd->add_option("--points-out", args->points_out, "Also write the detected points as a correspondence CSV");
  cmd->add_option("--png", args->png,
                  "Write DIR/cam<i>_z<z>mm_residuals.png per camera and plane: each point with an arrow to where the "
                  "stored model projects it, magnified (existing files need --overwrite)");
  cmd->add_option("--overlay", args->overlay,
                  "Target images: write DIR/cam<i>_<z>mm.png per image, the detected points circled, the origin ringed "
                  "and the +x, +y axes drawn (existing files need --overwrite)");
  cmd->add_option("--models", args->models,
                  "Models to fit, comma-separated: " + fmt::format("{}", fmt::join(calibration::all_camera_model_names(), ",")) +
                      "; each is fitted and reported, the last one is stored; auto: all of them, storing the one with the lowest "
                      "cross-validated error (leave one plane out, or one point with --cross-validate=points)")
      ->capture_default_str();
  cmd->add_option("--store", args->store, "Model to store in the calibration file (default: the last of --models)");
  cmd->add_option("--image-size", args->image_size, "Image size W,H in pixels of every camera");
  cmd->add_option("--camera-size", args->camera_sizes, "Image size of one camera, i=W,H (repeatable; overrides --image-size)");
  cmd->add_option("--max-iterations", args->max_iterations,
                  "Levenberg-Marquardt iterations per fit; a fit that does not converge within them fails (exit 1)")
      ->capture_default_str();
  cmd->add_option("--window-thickness", args->window_thickness_mm,
                  "refractive model: thickness of the flat window between cameras (in air) and medium, mm");
  cmd->add_option("--indices", args->indices, "refractive model: indices n_air,n_window,n_medium")->capture_default_str();
  cmd->add_option("--window-face", args->window_face_mm,
                  "refractive model: position of the window's medium-side face, mm along --window-normal (normal . X); "
                  "the start of the fit unless --fix-window")
      ->capture_default_str();
  cmd->add_option("--window-normal", args->window_normal,
                  "refractive model: window normal X,Y,Z in world coordinates, pointing from the cameras into the medium")
      ->capture_default_str();
  cmd->add_flag("--fix-window", args->fix_window, "refractive model: keep the window pose as given instead of fitting it");
  cmd->add_flag("--fit-medium-index", args->fit_medium_index, "refractive model: fit n_medium too");
  cmd->add_option("-o,--out", args->out, "Calibration file to write (.toml)");
  cmd->add_option("--check", args->check,
                  "Evaluate this calibration file on --points (points not used in its fit) instead of fitting: RMS, "
                  "mean and max residuals per camera");
  cmd->add_flag("--overwrite", args->overwrite, "Replace the calibration file if it exists");
  add_json_flag(*cmd, args->json);
  cmd->add_flag("--cross-validate{planes}", args->cross_validate,
                "Also report each model's cross-validated error per camera: --cross-validate (or =planes) leaves one "
                "plane out in turn, --cross-validate=points one point (fit on the rest, RMS px on what was left out); "
                "--models auto uses the same");
  cmd->callback([args, cmd] {
    for (const char* name : {"--target", "--spacing", "--dots", "--y-axis", "--corners", "--max-feature-px", "--lattice",
                             "--level-offset"})
      if (cmd->get_option(name)->count() > 0) args->target_options.push_back(name);
    run(*args);
  });
}

}  // namespace tomorig::app
