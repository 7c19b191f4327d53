// Finding target images and detecting the target in each; see calibrate_images.h.
#include "tomorig/pipeline/target_images.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"
#include "tomorig/core/frame_set.h"
#include "tomorig/processing/calibration/target_overlay.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {
namespace fs = std::filesystem;
namespace {

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".tif" || ext == ".tiff" || ext == ".png";
}

// The number a folder name ends in ("cam12" -> 12), if any.
std::optional<int> trailing_number(const std::string& name) {
  std::size_t start = name.size();
  while (start > 0 && std::isdigit(static_cast<unsigned char>(name[start - 1]))) --start;
  if (start == name.size() || name.size() - start > 6) return std::nullopt;
  return std::stoi(name.substr(start));
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// Sorts and rejects two images of one camera at one z.
void finish(TargetImageSet& set, const std::string& source) {
  std::sort(set.images.begin(), set.images.end(), [](const TargetImage& a, const TargetImage& b) {
    return a.camera != b.camera ? a.camera < b.camera : a.z_mm < b.z_mm;
  });
  for (std::size_t k = 1; k < set.images.size(); ++k)
    if (set.images[k].camera == set.images[k - 1].camera && set.images[k].z_mm == set.images[k - 1].z_mm)
      throw bad_input(fmt::format("{}: camera {} has two images at z = {} mm ({} and {}); give one image per plane",
                                  source, set.images[k].camera, set.images[k].z_mm, set.images[k - 1].file.string(),
                                  set.images[k].file.string()));
}

// Pixels per mm of one plane's points: sqrt |det A| of the least-squares affine map
// (x, y) -> (u, v). Zero if the plane has fewer than 3 points or they are collinear.
double plane_scale(const std::vector<calibration::PointCorrespondence>& points) {
  if (points.size() < 3) return 0;
  double m[3][3] = {}, bu[3] = {}, bv[3] = {};
  for (const auto& p : points) {
    const double row[3] = {p.world.x, p.world.y, 1};
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) m[a][b] += row[a] * row[b];
      bu[a] += row[a] * p.pixel.x;
      bv[a] += row[a] * p.pixel.y;
    }
  }
  auto det3 = [](const double q[3][3]) {
    return q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) - q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
           q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0]);
  };
  const double d = det3(m);
  if (std::abs(d) < 1e-12) return 0;
  // Cramer's rule for the x and y coefficients of u and v.
  auto solve = [&](const double b[3], int column) {
    double q[3][3];
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) q[a][c] = c == column ? b[a] : m[a][c];
    return det3(q) / d;
  };
  const double a11 = solve(bu, 0), a12 = solve(bu, 1), a21 = solve(bv, 0), a22 = solve(bv, 1);
  return std::sqrt(std::abs(a11 * a22 - a12 * a21));
}

}  // namespace

std::string orient_y_axis(DetectedTargets& detected) {
  // Relative change of scale per mm of z, below which the view counts as telecentric.
  constexpr double kMeasurable = 2e-5;
  int towards = 0, away = 0;
  std::string slopes;
  // One plane gives no direction; leave y down and let the fit say that depth is missing.
  for (const auto& points : detected.table.cameras)
    if (std::none_of(points.begin(), points.end(), [&](const auto& p) { return p.world.z != points.front().world.z; }))
      return "down";
  for (std::size_t c = 0; c < detected.table.cameras.size(); ++c) {
    std::map<double, std::vector<calibration::PointCorrespondence>> planes;
    for (const auto& p : detected.table.cameras[c]) planes[p.world.z].push_back(p);
    // Least-squares slope of log(scale) against z.
    double n = 0, sz = 0, ss = 0, szz = 0, szs = 0;
    for (const auto& [z, points] : planes) {
      const double scale = plane_scale(points);
      if (!(scale > 0)) continue;
      n += 1, sz += z, ss += std::log(scale), szz += z * z, szs += z * std::log(scale);
    }
    const double denominator = n * szz - sz * sz;
    const double slope = n >= 2 && denominator > 0 ? (n * szs - sz * ss) / denominator : 0;
    slopes += fmt::format("{}camera {}: {:+.2g}/mm", c ? ", " : "", c, slope);
    if (slope > kMeasurable) ++towards;
    else if (slope < -kMeasurable) ++away;
  }
  const auto cameras = static_cast<int>(detected.table.cameras.size());
  if (towards != cameras && away != cameras)
    throw bad_input(fmt::format("--y-axis auto: cannot tell from the images whether z points towards the cameras (the "
                                "relative change of the target's image scale with z, {}, is not clearly of one sign on "
                                "every camera); give --y-axis down or up",
                                slopes));
  if (away == cameras) return "down";
  for (auto& points : detected.table.cameras)
    for (auto& p : points) p.world.y = p.world.y == 0 ? 0.0 : -p.world.y;  // no "-0" in reports
  return "up";
}

bool parse_plane_z(const std::string& file_name, double& z_mm) {
  const auto mm = file_name.find("mm");
  if (mm == std::string::npos || mm == 0) return false;
  std::string_view number(file_name.data(), mm);
  if (!number.empty() && number.front() == '+') number.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), z_mm);
  return ec == std::errc() && ptr == number.data() + number.size() && std::isfinite(z_mm);
}

TargetImageSet find_target_images(const fs::path& dir) {
  if (!fs::is_directory(dir))
    throw bad_input(fmt::format("--images {}: not a folder; expected a folder with one sub-folder per camera (cam0, "
                                "cam1, ...) holding images named <z>mm*.tif",
                                dir.string()));
  std::map<int, fs::path> folders;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_directory()) continue;
    const auto number = trailing_number(entry.path().filename().string());
    if (!number) continue;
    if (const auto [it, fresh] = folders.emplace(*number, entry.path()); !fresh)
      throw bad_input(fmt::format("--images {}: camera folders {} and {} end in the same number {}", dir.string(),
                                  it->second.filename().string(), entry.path().filename().string(), *number));
  }
  if (folders.empty())
    throw bad_input(fmt::format("--images {}: no camera folders; expected sub-folders whose names end in the camera "
                                "number (cam0, cam1, ...) holding images named <z>mm*.tif (e.g. cam0/-3mm_cam0.tif)",
                                dir.string()));
  TargetImageSet set;
  int camera = 0;
  for (const auto& [number, folder] : folders) {
    set.camera_names.push_back(folder.filename().string());
    bool any = false;
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (!entry.is_regular_file() || !is_image_file(entry.path())) continue;
      double z = 0;
      const std::string name = entry.path().filename().string();
      if (!parse_plane_z(name, z))
        throw bad_input(fmt::format("{}: the plane z cannot be read from the file name; name target images "
                                    "<z>mm<anything>.tif, e.g. -3mm_cam0.tif or 1.5mm.tif, or list them with --image-list",
                                    entry.path().string()));
      set.images.push_back({camera, z, entry.path()});
      any = true;
    }
    if (!any)
      throw bad_input(fmt::format("{}: camera folder without images (.tif, .tiff, .png named <z>mm*)", folder.string()));
    ++camera;
  }
  finish(set, "--images " + dir.string());
  return set;
}

TargetImageSet read_image_list(const fs::path& csv) {
  std::ifstream in(csv);
  if (!in) throw bad_input(fmt::format("image list '{}' does not exist or cannot be read", csv.string()));
  TargetImageSet set;
  std::string text;
  bool header = false;
  std::set<int> cameras;
  for (int line = 1; std::getline(in, text); ++line) {
    const std::string_view row = trimmed(text);
    if (row.empty() || row.front() == '#') continue;
    std::vector<std::string_view> fields;
    for (std::string_view rest = row;;) {
      const auto comma = rest.find(',');
      fields.push_back(trimmed(rest.substr(0, comma)));
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
    if (!header) {
      if (fields.size() != 3 || fields[0] != "camera" || fields[1] != "z" || fields[2] != "file")
        throw bad_input(fmt::format("{}:{}: expected the header camera,z,file", csv.string(), line));
      header = true;
      continue;
    }
    if (fields.size() != 3)
      throw bad_input(fmt::format("{}:{}: {} fields, expected 3 (camera,z,file)", csv.string(), line, fields.size()));
    TargetImage image;
    const auto [p1, e1] = std::from_chars(fields[0].data(), fields[0].data() + fields[0].size(), image.camera);
    if (e1 != std::errc() || p1 != fields[0].data() + fields[0].size() || image.camera < 0)
      throw bad_input(fmt::format("{}:{}: camera '{}' is not an integer >= 0", csv.string(), line, fields[0]));
    const auto [p2, e2] = std::from_chars(fields[1].data(), fields[1].data() + fields[1].size(), image.z_mm);
    if (e2 != std::errc() || p2 != fields[1].data() + fields[1].size() || !std::isfinite(image.z_mm))
      throw bad_input(fmt::format("{}:{}: z '{}' is not a finite number of mm", csv.string(), line, fields[1]));
    if (fields[2].empty()) throw bad_input(fmt::format("{}:{}: empty file name", csv.string(), line));
    const fs::path file(fields[2]);
    image.file = file.is_absolute() ? file : csv.parent_path() / file;
    cameras.insert(image.camera);
    set.images.push_back(image);
  }
  if (set.images.empty()) throw bad_input(fmt::format("{}: no images listed; expected the header camera,z,file and one row per image", csv.string()));
  const int count = *cameras.rbegin() + 1;
  for (int c = 0; c < count; ++c) {
    if (!cameras.count(c))
      throw bad_input(fmt::format("{}: camera {} has no images, but camera {} has; cameras are numbered 0 to N-1",
                                  csv.string(), c, count - 1));
    set.camera_names.push_back(fmt::format("camera {}", c));
  }
  finish(set, csv.string());
  return set;
}

TargetImageSet read_session_targets(const fs::path& path, const std::vector<double>& z_list) {
  const storage::SessionReader session(path);
  const auto sets = static_cast<std::size_t>(session.set_count());
  if (sets == 0) throw bad_input(fmt::format("--session {}: the session holds no sets", path.string()));
  std::vector<double> z(sets, 0.0);
  if (!z_list.empty()) {
    if (z_list.size() != sets)
      throw bad_input(fmt::format("--z-list gives {} plane z values, but --session {} holds {} sets; give one z (mm) "
                                  "per set, in set order",
                                  z_list.size(), path.string(), sets));
    z = z_list;
  } else {
    // The truth of a simulated target session names each set's nominal plane z; the true
    // offsets beside it are what a calibration must find, so they are not read.
    const std::string how = fmt::format("give the plane z of every set with --z-list z0,z1,... (mm, {} values in set order)", sets);
    if (!session.has_truth())
      throw bad_input(fmt::format("--session {}: no plane z positions (the session has no truth); {}", path.string(), how));
    nlohmann::json parameters;
    try {
      parameters = nlohmann::json::parse(session.truth().flow_parameters);
    } catch (const nlohmann::json::exception&) {
      parameters = nullptr;
    }
    if (!parameters.is_object() || !parameters.contains("planes") || !parameters["planes"].is_array())
      throw bad_input(fmt::format("--session {}: no plane z positions (its truth, case '{}', is not a calibration target "
                                  "case: flow_parameters has no \"planes\"); {}",
                                  path.string(), session.truth().case_name, how));
    std::vector<bool> seen(sets, false);
    for (const auto& plane : parameters["planes"]) {
      if (!plane.contains("set") || !plane["set"].is_number_integer() || !plane.contains("z_nominal_mm") ||
          !plane["z_nominal_mm"].is_number())
        throw bad_input(fmt::format("--session {}: a truth plane lacks \"set\" or \"z_nominal_mm\"; {}", path.string(), how));
      const auto k = plane["set"].get<long long>();
      if (k < 0 || static_cast<std::size_t>(k) >= sets)
        throw bad_input(fmt::format("--session {}: truth plane of set {} is not among the {} sets; {}", path.string(), k, sets, how));
      z[static_cast<std::size_t>(k)] = plane["z_nominal_mm"].get<double>();
      seen[static_cast<std::size_t>(k)] = true;
    }
    for (std::size_t k = 0; k < sets; ++k)
      if (!seen[k]) throw bad_input(fmt::format("--session {}: the truth gives no plane z for set {}; {}", path.string(), k, how));
  }
  TargetImageSet set;
  const auto& cameras = session.info().cameras;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    set.camera_names.push_back(cameras[c].id);
    for (std::size_t k = 0; k < sets; ++k)
      set.images.push_back({static_cast<int>(c), z[k], path, static_cast<long long>(k)});
  }
  finish(set, "--session " + path.string());
  return set;
}

DetectedTargets detect_targets(const TargetImageSet& set, const calibration::TargetSpec& spec, int min_points_per_plane,
                               const OverlayOutput& overlay) {
  const auto overlay_file = [&](const TargetImage& image) {
    return overlay.dir / fmt::format("cam{}_{}mm.png", image.camera, image.z_mm);
  };
  if (!overlay.dir.empty()) {
    std::error_code ec;
    fs::create_directories(overlay.dir, ec);
    if (ec || !fs::is_directory(overlay.dir))
      throw bad_input(fmt::format("--overlay {}: cannot create the folder: {}", overlay.dir.string(), ec.message()));
    for (const TargetImage& image : set.images)
      if (!overlay.overwrite && fs::exists(overlay_file(image)))
        throw bad_input(fmt::format("--overlay {}: {} exists; give --overwrite to replace it, or another folder",
                                    overlay.dir.string(), overlay_file(image).string()));
  }
  DetectedTargets out;
  out.table.cameras.resize(set.camera_names.size());
  out.image_sizes.resize(set.camera_names.size());
  std::vector<std::optional<fs::path>> size_source(set.camera_names.size());
  // Session images: the reader stays open and the last set read is kept, so that each set is
  // read once when the images come set by set.
  std::unique_ptr<storage::SessionReader> session;
  std::optional<FrameSet> cached;
  std::vector<const TargetImage*> order;
  for (const TargetImage& image : set.images) order.push_back(&image);
  std::stable_sort(order.begin(), order.end(), [](const TargetImage* a, const TargetImage* b) {
    return a->session_set < b->session_set;
  });
  for (const TargetImage* ordered : order) {
    const TargetImage& image = *ordered;
    const std::string what =
        image.session_set >= 0
            ? fmt::format("camera {} ({}), plane z = {} mm (set {} of {})", image.camera, set.camera_names[image.camera],
                          image.z_mm, image.session_set, image.file.string())
            : fmt::format("camera {}, plane z = {} mm ({})", image.camera, image.z_mm, image.file.string());
    Image pixels;
    if (image.session_set >= 0) {
      if (!session) session = std::make_unique<storage::SessionReader>(image.file);
      if (!cached || cached->set_index != static_cast<std::uint64_t>(image.session_set))
        cached = session->read_set(static_cast<std::uint64_t>(image.session_set));
      const auto c = static_cast<std::size_t>(image.camera);
      if (c >= cached->cameras.size() || !cached->cameras[c].a.present())
        throw bad_input(fmt::format("{}: exposure A (the target image) is missing", what));
      pixels = cached->cameras[c].a.image;
    } else {
      try {
        pixels = storage::read_image(image.file);
      } catch (const Error& e) {
        throw bad_input(fmt::format("camera {}, plane z = {} mm: {}", image.camera, image.z_mm, e.what()));
      }
    }
    const auto c = static_cast<std::size_t>(image.camera);
    calibration::ImageSize& size = out.image_sizes[c];
    if (!size_source[c]) {
      size = {pixels.width(), pixels.height()};
      size_source[c] = image.file;
    } else if (size.width != pixels.width() || size.height != pixels.height()) {
      throw bad_input(fmt::format("{}: the image is {} x {} px, but the camera's image {} is {} x {} px; every image of a "
                                  "camera must have the same size",
                                  what, pixels.width(), pixels.height(), size_source[c]->string(), size.width, size.height));
    }
    calibration::TargetDetection detection = calibration::detect_target(pixels, spec, image.z_mm, what);
    if (static_cast<int>(detection.points.size()) < min_points_per_plane)
      throw bad_input(fmt::format("{}: too few target points identified: {}, at least {} needed per plane; check the "
                                  "target spec (spacing, polarity) and the image",
                                  what, detection.points.size(), min_points_per_plane));
    out.warnings.insert(out.warnings.end(), detection.warnings.begin(), detection.warnings.end());
    if (detection.origin_px && detection.x_step_px)
      out.origins.push_back(fmt::format("{}: origin ({}) at ({:.1f}, {:.1f}) px, +x towards ({:+.1f}, {:+.1f}) px per "
                                        "pitch, set by {}",
                                        what, detection.origin_marker, detection.origin_px->x, detection.origin_px->y,
                                        detection.x_step_px->x, detection.x_step_px->y,
                                        detection.axis_marker ? "the triangle" : "the image (most nearly to the right)"));
    if (!overlay.dir.empty()) storage::write_png(overlay_file(image), calibration::draw_detection_overlay(pixels, detection));
    auto& points = out.table.cameras[c];
    points.insert(points.end(), detection.points.begin(), detection.points.end());
  }
  return out;
}

}  // namespace tomorig::pipeline
