// tomorig calibrate --points POINTS.csv: fits camera models to point correspondences made
// elsewhere, writes the calibration file and prints the residual report of thesis Tables 5.3
// and 6.4 (per camera and model: forward residual in px, reverse residual in um).
#include <algorithm>
#include <charconv>
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

#include "commands.h"
#include "correspondence_csv.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/fit_camera_model.h"

namespace tomorig::app {
namespace {

struct CalibrateArgs {
  std::string points;
  std::string models = "pinhole";
  std::string store;  // empty: the last of --models
  std::string image_size;
  std::vector<std::string> camera_sizes;
  int max_iterations = calibration::FitOptions{}.max_iterations;
  std::string out;
  bool json = false;
};

struct ModelResult {
  int camera = 0;
  calibration::FitReport report;
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
  const auto& known = calibration::camera_model_names();
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

void print_table(const std::vector<ModelResult>& results, const std::string& stored, const std::string& out) {
  fmt::print("{:>6}  {:<10} {:>7} {:>7} {:>12} {:>12} {:>10}\n", "camera", "model", "points", "planes", "forward px",
             "reverse um", "converged");
  for (const ModelResult& r : results)
    fmt::print("{:>6}  {:<10} {:>7} {:>7} {:>12.4g} {:>12.4g} {:>10}\n", r.camera, r.report.model, r.report.points,
               r.report.planes, r.report.forward_mean_px, r.report.reverse_mean_um, r.report.converged ? "yes" : "no");
  fmt::print("wrote {} (model {} for every camera)\n", out, stored);
}

void run(const CalibrateArgs& args) {
  const std::vector<std::string> models = parse_models(args.models);
  const std::string stored = args.store.empty() ? models.back() : args.store;
  if (std::find(models.begin(), models.end(), stored) == models.end())
    throw bad_input(fmt::format("--store {} is not one of --models {}; the stored model must be fitted", stored,
                                args.models));
  if (args.max_iterations < 1)
    throw bad_input(fmt::format("--max-iterations {} is invalid: it must be >= 1", args.max_iterations));
  const CorrespondenceTable table = read_correspondence_csv(args.points);
  const std::vector<calibration::ImageSize> sizes = image_sizes(args, table.cameras.size());

  std::vector<ModelResult> results;
  std::vector<calibration::CameraCalibration> calibrations;
  for (std::size_t i = 0; i < table.cameras.size(); ++i) {
    calibration::FitOptions options;
    options.camera = fmt::format("camera {}", i);
    options.max_iterations = args.max_iterations;
    for (const std::string& model_name : models) {
      calibration::FitReport report;
      // Errors (too few points, one plane, degenerate geometry, no convergence) propagate
      // with the camera named; nothing is written unless every fit succeeds.
      std::unique_ptr<calibration::CameraModel> model =
          calibration::fit_camera_model(model_name, table.cameras[i], sizes[i], options, report);
      results.push_back({static_cast<int>(i), report});
      if (model_name == stored) calibrations.push_back({static_cast<int>(i), sizes[i], std::move(model), report});
    }
  }
  calibration::save_calibration(args.out, calibrations);

  if (args.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const ModelResult& r : results)
      list.push_back({{"camera", r.camera},
                      {"model", r.report.model},
                      {"points", r.report.points},
                      {"planes", r.report.planes},
                      {"forward_px", r.report.forward_mean_px},
                      {"reverse_um", r.report.reverse_mean_um},
                      {"converged", r.report.converged}});
    fmt::print("{}\n", nlohmann::json{{"results", list}, {"stored", stored}, {"out", args.out}}.dump(2));
  } else {
    print_table(results, stored, args.out);
  }
}

}  // namespace

void add_calibrate_command(CLI::App& root) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = root.add_subcommand("calibrate", "Fit camera models to point correspondences and write a calibration file");
  cmd->add_option("--points", args->points, "Point correspondences, CSV with the header camera,X,Y,Z,x,y (mm, px)")
      ->required();
  cmd->add_option("--models", args->models,
                  "Models to fit, comma-separated: " + fmt::format("{}", fmt::join(calibration::camera_model_names(), ",")) +
                      "; each is fitted and reported, the last one is stored")
      ->capture_default_str();
  cmd->add_option("--store", args->store, "Model to store in the calibration file (default: the last of --models)");
  cmd->add_option("--image-size", args->image_size, "Image size W,H in pixels of every camera");
  cmd->add_option("--camera-size", args->camera_sizes, "Image size of one camera, i=W,H (repeatable; overrides --image-size)");
  cmd->add_option("--max-iterations", args->max_iterations,
                  "Levenberg-Marquardt iterations per fit; a fit that does not converge within them fails (exit 1)")
      ->capture_default_str();
  cmd->add_option("-o,--out", args->out, "Calibration file to write (.toml)")->required();
  cmd->add_flag("--json", args->json, "Print the report as one JSON object");
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
