// tomorig bench spray SESSION.h5: the droplet accuracy of tomographic shadowgraphy on a
// spray-thesis session (issue 20, thesis Sect. 7.3.3-7.5, Fig. 7.15). Each set's exposure A is
// preprocessed (--chain, e.g. shadow-b) and reconstructed with the spray PSF (--psf), droplets
// are detected as 3-D blobs and matched one-to-one with the simulator's droplets: the detected
// fraction by size class and depth, against the smallest visible droplet the optics predict
// (optics::visibility_table of the set-up). With --results (the file `tomorig process` wrote
// for the same session) each droplet's velocity from the 3-D correlation, sampled at its
// position, is compared with its true velocity: RMS per size class.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench_common.h"
#include "spray_truth.h"
#include "tomorig/core/error.h"
#include "tomorig/core/set_selection.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "tomorig/pipeline/spray_psf.h"
#include "tomorig/processing/optics/droplet_size.h"
#include "tomorig/processing/optics/visibility.h"
#include "tomorig/processing/particles/droplets.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::bench {
namespace {

struct BenchSprayArgs {
  std::string session;
  std::string calib;
  std::string chain = "shadow-detect";
  std::string results;
  std::string sets;
  std::vector<double> classes_um{5, 10, 15, 20, 30, 50, 100};
  int depth_bins = 5;
  double match_voxels = 3.0;
  particles::DropletDetectionOptions detection{.relative_peak_threshold = 0.0};
  // MENT, as the thesis reconstructed its sprays (Sect. 7.4): additive, so a faint droplet keeps
  // an intensity in proportion to its shadows; FMART's products and pruning drop droplets near
  // the visibility limit next to bright ones (docs/accuracy.md).
  pipeline::ReconstructionChoices recon{.algorithm = "ment", .algorithm_from_rig = false};
  std::string json_out;
  // A blob's integrated intensity per pixel of light its droplet removed (full-depth shadow =
  // 1 per pixel): the reconstruction's scale. 0: fitted on this session's matched droplets.
  double shadow_scale = 0.0;
};

struct MatchedBlob {  // a detected droplet, for the size estimate
  double integrated;
  double d_truth_um;
  std::size_t truth_class;
  bool above_limit;
};

struct Cell {  // droplets of one size class in one depth bin
  int truth = 0, detected = 0, above_limit = 0, above_detected = 0;
};

struct ClassFigures {
  std::vector<Cell> depth;
  std::vector<int> estimated;  // matched droplets by estimated class: below, the classes, above
  double d_est_sum_um = 0;
  Cell all;
  double d_eq_sum_um = 0;  // of the matched detections
  Vec3d position_sq;       // squared position errors of the matched, mm^2
  int velocity_n = 0;
  Vec3d velocity_sq;       // squared velocity errors, (m/s)^2
  double speed_sum = 0;    // true speed, m/s
};

// The set-up's smallest visible diameter at depth z: linear between the table's rows.
double predicted_limit_um(const std::vector<optics::VisibilityRow>& rows, double z) {
  if (rows.empty()) return 0;
  if (z <= rows.front().z_mm) return rows.front().setup_d_min_um;
  for (std::size_t k = 1; k < rows.size(); ++k)
    if (z <= rows[k].z_mm) {
      const double t = (z - rows[k - 1].z_mm) / (rows[k].z_mm - rows[k - 1].z_mm);
      return rows[k - 1].setup_d_min_um + t * (rows[k].setup_d_min_um - rows[k - 1].setup_d_min_um);
    }
  return rows.back().setup_d_min_um;
}

// Displacement (voxel) of the field at `world`: trilinear over the corner nodes holding a valid
// vector, or nullopt if they carry less than half the weight.
std::optional<Vec3d> sample_field(const VectorField& f, const Vec3d& world) {
  const double u = (world.x - f.origin.x) / f.spacing.x, v = (world.y - f.origin.y) / f.spacing.y,
               w = (world.z - f.origin.z) / f.spacing.z;
  const int i0 = static_cast<int>(std::floor(u)), j0 = static_cast<int>(std::floor(v)), k0 = static_cast<int>(std::floor(w));
  Vec3d sum;
  double weight = 0;
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) {
        const int i = i0 + di, j = j0 + dj, k = k0 + dk;
        if (i < 0 || j < 0 || k < 0 || i >= f.nx || j >= f.ny || k >= f.nz) continue;
        const std::size_t n = f.linear(i, j, k);
        if (f.status[n] != VectorStatus::valid) continue;
        const double wt = (di ? u - i0 : 1 - (u - i0)) * (dj ? v - j0 : 1 - (v - j0)) * (dk ? w - k0 : 1 - (w - k0));
        sum = sum + Vec3d{f.displacement[n].x, f.displacement[n].y, f.displacement[n].z} * wt;
        weight += wt;
      }
  if (weight < 0.5) return std::nullopt;
  return sum * (1.0 / weight);
}

bool in_every_view(const std::vector<const calibration::CameraModel*>& cams,
                   const std::vector<storage::SessionCamera>& sizes, const Vec3d& p) {
  for (std::size_t c = 0; c < cams.size(); ++c) {
    const Vec2d q = cams[c]->project(p);
    if (!(q.x >= 0 && q.y >= 0 && q.x <= sizes[c].width - 1 && q.y <= sizes[c].height - 1)) return false;
  }
  return true;
}

std::string class_name(const std::vector<double>& edges, std::size_t k) {
  return fmt::format("{:g}-{:g}", edges[k], edges[k + 1]);
}

// The column of diameter d among the estimated classes: 0 below the first edge, k + 1 for class
// k, classes + 1 at or above the last edge.
std::size_t estimated_column(const std::vector<double>& edges, double d) {
  return static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), d) - edges.begin());
}

std::vector<std::string> estimated_columns(const std::vector<double>& edges) {
  std::vector<std::string> names{fmt::format("<{:g}", edges.front())};
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) names.push_back(class_name(edges, k));
  names.push_back(fmt::format(">={:g}", edges.back()));
  return names;
}

nlohmann::json cell_json(const Cell& c) {
  return {{"truth", c.truth},
          {"detected", c.detected},
          {"detected_fraction", json_number(c.truth ? double(c.detected) / c.truth : NAN)},
          {"above_limit", c.above_limit},
          {"above_limit_detected", c.above_detected},
          {"above_limit_detected_fraction", json_number(c.above_limit ? double(c.above_detected) / c.above_limit : NAN)}};
}

std::string percent(int num, int den) { return den ? fmt::format("{:5.1f}", 100.0 * num / den) : "    -"; }

void run(const BenchSprayArgs& args) {
  if (args.classes_um.size() < 2 || !std::is_sorted(args.classes_um.begin(), args.classes_um.end()))
    throw bad_input("--classes needs at least two ascending diameters in um, e.g. 5,10,15,20,30,50,100");
  if (args.depth_bins < 1 || args.depth_bins > 50) throw bad_input("--depth-bins must be 1 to 50");
  if (!(args.match_voxels > 0)) throw bad_input("--match-voxels must be > 0");
  if (!(args.shadow_scale >= 0))
    throw bad_input("--shadow-scale must be > 0 (0 or none: fitted on this session's truth)");
  args.detection.validate();
  const storage::SessionReader session(args.session);
  const pipeline::SessionDescription description = pipeline::describe_session(session);
  if (!description.truth) throw bad_input(fmt::format("'{}' holds no simulator truth: bench spray judges against it", args.session));
  const sim::SprayCase spray = spray_case_of(*description.truth);
  const pipeline::SessionCameras cameras = pipeline::session_cameras(description, args.calib);
  pipeline::ReconstructionChoices choices = args.recon;
  if (choices.psf.empty()) choices.psf = "truth";
  pipeline::ReconstructionSetup setup = pipeline::reconstruction_setup(description, cameras, choices);
  const auto reconstructor = recon::make_reconstructor(setup.options);
  recon::ReconstructionInput& input = setup.input;
  const VoxelGrid& grid = input.grid;
  // The predicted limit comes from the same optics as the PSF.
  const std::vector<optics::VisibilityRow> limit_rows =
      optics::visibility_table(pipeline::spray_optics_setup(choices.psf, description.truth));
  // Each blob's own size: the diameter whose shadow removes the light the blob holds, averaged
  // over the views (optics/droplet_size.h), with the cameras' object pixels of the case.
  std::vector<double> object_pixel_um;
  for (const sim::SprayCamera& c : spray.cameras) object_pixel_um.push_back(c.pixel_pitch_um / c.magnification);
  const optics::DropletSizeModel size_model(pipeline::spray_optics_setup(choices.psf, description.truth), object_pixel_um);
  pipeline::SessionPreprocessor preprocessor(session, args.chain);
  std::optional<storage::ResultsReader> results;
  if (!args.results.empty()) results.emplace(args.results);

  const std::vector<std::uint64_t> sets =
      (args.sets.empty() ? SetSelection() : SetSelection::parse(args.sets)).indices(session.set_count());
  const std::size_t classes = args.classes_um.size() - 1;
  std::vector<ClassFigures> figures(classes);
  for (ClassFigures& f : figures) {
    f.depth.resize(static_cast<std::size_t>(args.depth_bins));
    f.estimated.assign(classes + 2, 0);
  }
  std::vector<double> blob_integrated;  // every blob, matched or not
  std::vector<MatchedBlob> matched_blobs;
  const double z_lo = grid.origin.z, z_hi = grid.origin.z + (grid.nz - 1) * grid.voxel_size;
  const double margin = 2 * grid.voxel_size;  // a droplet at a face is half a blob
  const double match_mm = args.match_voxels * grid.voxel_size;
  int detections = 0, unmatched_detections = 0, sets_with_velocity = 0;
  nlohmann::json per_set = nlohmann::json::array();

  for (const std::uint64_t k : sets) {
    FrameSet set = session.read_set(k);
    preprocessor.apply(set);
    input.images.clear();
    for (const CameraFrames& cf : set.cameras) {
      if (cf.a.image.empty()) throw bad_input(fmt::format("set {}: camera '{}' has no frame A", k, cf.camera_id));
      input.images.push_back(cf.a.image);
    }
    recon::ReconstructionReport report;
    const DenseVolume volume = reconstructor->reconstruct(input, report).to_dense();
    const std::vector<particles::DetectedDroplet> found = particles::detect_droplets(volume, args.detection);
    detections += static_cast<int>(found.size());
    for (const particles::DetectedDroplet& f : found) blob_integrated.push_back(f.integrated);

    std::vector<TruthDroplet> truth = spray_truth_droplets(session, spray, k);
    std::erase_if(truth, [&](const TruthDroplet& d) {
      const Vec3d& p = d.a;
      return p.x < grid.origin.x + margin || p.y < grid.origin.y + margin || p.z < z_lo + margin ||
             p.x > grid.origin.x + (grid.nx - 1) * grid.voxel_size - margin ||
             p.y > grid.origin.y + (grid.ny - 1) * grid.voxel_size - margin || p.z > z_hi - margin ||
             d.d_um < args.classes_um.front() || d.d_um >= args.classes_um.back() ||
             !in_every_view(input.cameras, description.cameras, p);
    });
    // One-to-one, closest pairs first.
    struct Pair { double distance; std::size_t t, f; };
    std::vector<Pair> pairs;
    for (std::size_t t = 0; t < truth.size(); ++t)
      for (std::size_t f = 0; f < found.size(); ++f) {
        const double dist = (found[f].world - truth[t].a).norm();
        if (dist <= match_mm) pairs.push_back({dist, t, f});
      }
    std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) { return x.distance < y.distance; });
    std::vector<int> match(truth.size(), -1);
    std::vector<bool> used(found.size(), false);
    for (const Pair& p : pairs)
      if (match[p.t] < 0 && !used[p.f]) {
        match[p.t] = static_cast<int>(p.f);
        used[p.f] = true;
      }
    unmatched_detections += static_cast<int>(std::count(used.begin(), used.end(), false));

    std::optional<storage::SetResult> field;
    if (results) {
      const std::vector<std::uint64_t> in_file = results->set_indices();
      if (std::find(in_file.begin(), in_file.end(), k) != in_file.end()) {
        field = results->read_set(k);
        ++sets_with_velocity;
      }
    }
    int set_truth = 0, set_detected = 0;
    for (std::size_t t = 0; t < truth.size(); ++t) {
      const TruthDroplet& d = truth[t];
      const std::size_t c = static_cast<std::size_t>(
          std::upper_bound(args.classes_um.begin(), args.classes_um.end(), d.d_um) - args.classes_um.begin() - 1);
      const int bin = std::clamp(static_cast<int>((d.a.z - z_lo) / (z_hi - z_lo) * args.depth_bins), 0,
                                 args.depth_bins - 1);
      const bool above = d.d_um > predicted_limit_um(limit_rows, d.a.z);
      const bool detected = match[t] >= 0;
      ClassFigures& fig = figures[c];
      for (Cell* cell : {&fig.depth[static_cast<std::size_t>(bin)], &fig.all}) {
        ++cell->truth;
        cell->detected += detected;
        cell->above_limit += above;
        cell->above_detected += above && detected;
      }
      ++set_truth;
      set_detected += detected;
      if (detected) {
        const particles::DetectedDroplet& f = found[static_cast<std::size_t>(match[t])];
        fig.d_eq_sum_um += f.d_eq_mm * 1e3;
        matched_blobs.push_back({f.integrated, d.d_um, c, above});
        const Vec3d e = f.world - d.a;
        fig.position_sq = fig.position_sq + Vec3d{e.x * e.x, e.y * e.y, e.z * e.z};
      }
      if (field && above) {
        const Vec3d mid = (d.a + d.b) * 0.5;
        if (const std::optional<Vec3d> disp = sample_field(field->field, mid)) {
          const double to_m_s = 1e6 / static_cast<double>(field->dt_ns);  // mm/ns -> m/s
          const Vec3d measured = *disp * (results->info().voxel_size_mm * to_m_s);
          const Vec3d truth_v = (d.b - d.a) * to_m_s;
          const Vec3d e = measured - truth_v;
          ++fig.velocity_n;
          fig.velocity_sq = fig.velocity_sq + Vec3d{e.x * e.x, e.y * e.y, e.z * e.z};
          fig.speed_sum += truth_v.norm();
        }
      }
    }
    per_set.push_back({{"set", k},
                       {"droplets_in_volume", set_truth},
                       {"detected", set_detected},
                       {"detections", found.size()},
                       {"reconstruction_seconds", report.seconds}});
    fmt::print(stderr, "set {}: {} droplets in the volume, {} detected, {} blobs ({:.1f} s)\n", k, set_truth,
               set_detected, found.size(), report.seconds);
  }

  // The table and the JSON.
  // The size estimate: each blob's diameter from its light, at the given scale or the one that
  // fits this session's droplets above the limit best (the median ratio: robust to merged blobs).
  double scale = args.shadow_scale;
  if (!(scale > 0)) {
    std::vector<double> ratios;
    for (const MatchedBlob& m : matched_blobs)
      if (m.above_limit) ratios.push_back(m.integrated / size_model.removed_px(m.d_truth_um));
    if (!ratios.empty()) {
      std::nth_element(ratios.begin(), ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
      scale = ratios[ratios.size() / 2];
    }
  }
  std::vector<int> blobs_by_estimate(classes + 2, 0);
  if (scale > 0) {
    for (const double integrated : blob_integrated)
      ++blobs_by_estimate[estimated_column(args.classes_um, size_model.diameter_um(integrated / scale))];
    for (const MatchedBlob& m : matched_blobs) {
      const double estimate = size_model.diameter_um(m.integrated / scale);
      figures[m.truth_class].d_est_sum_um += estimate;
      ++figures[m.truth_class].estimated[estimated_column(args.classes_um, estimate)];
    }
  }
  Cell above_total;
  int matched = 0, same_class = 0, within_one = 0;
  nlohmann::json confusion = nlohmann::json::array();
  for (std::size_t c = 0; c < classes; ++c) {
    const std::vector<int>& row = figures[c].estimated;
    for (std::size_t col = 0; col < row.size(); ++col) {
      matched += row[col];
      if (col == c + 1) same_class += row[col];
      if (col + 1 >= c + 1 && col <= c + 2) within_one += row[col];
    }
    confusion.push_back({{"truth_class", class_name(args.classes_um, c)}, {"estimated", row}});
  }
  nlohmann::json classes_json = nlohmann::json::array();
  for (std::size_t c = 0; c < classes; ++c) {
    const ClassFigures& f = figures[c];
    above_total.above_limit += f.all.above_limit;
    above_total.above_detected += f.all.above_detected;
    nlohmann::json depth = nlohmann::json::array();
    for (int b = 0; b < args.depth_bins; ++b) {
      nlohmann::json cell = cell_json(f.depth[static_cast<std::size_t>(b)]);
      cell["z_mm"] = {z_lo + b * (z_hi - z_lo) / args.depth_bins, z_lo + (b + 1) * (z_hi - z_lo) / args.depth_bins};
      depth.push_back(cell);
    }
    const double n = f.all.detected, nv = f.velocity_n;
    nlohmann::json cj = cell_json(f.all);
    cj["d_um"] = {args.classes_um[c], args.classes_um[c + 1]};
    cj["depth"] = depth;
    cj["d_eq_mean_um"] = json_number(n > 0 ? f.d_eq_sum_um / n : NAN);
    cj["d_est_mean_um"] = json_number(n > 0 ? f.d_est_sum_um / n : NAN);
    cj["estimated_same_class_fraction"] = json_number(n > 0 ? f.estimated[c + 1] / n : NAN);
    cj["position_rms_um"] = {json_number(n > 0 ? std::sqrt(f.position_sq.x / n) * 1e3 : NAN),
                             json_number(n > 0 ? std::sqrt(f.position_sq.y / n) * 1e3 : NAN),
                             json_number(n > 0 ? std::sqrt(f.position_sq.z / n) * 1e3 : NAN)};
    cj["velocity"] = {{"droplets", f.velocity_n},
                      {"mean_speed_m_s", json_number(nv > 0 ? f.speed_sum / nv : NAN)},
                      {"rms_error_m_s", {json_number(nv > 0 ? std::sqrt(f.velocity_sq.x / nv) : NAN),
                                         json_number(nv > 0 ? std::sqrt(f.velocity_sq.y / nv) : NAN),
                                         json_number(nv > 0 ? std::sqrt(f.velocity_sq.z / nv) : NAN)}},
                      {"rms_error_magnitude_m_s",
                       json_number(nv > 0 ? std::sqrt((f.velocity_sq.x + f.velocity_sq.y + f.velocity_sq.z) / nv) : NAN)}};
    classes_json.push_back(cj);
  }
  nlohmann::json limits = nlohmann::json::array();
  for (const optics::VisibilityRow& r : limit_rows)
    limits.push_back({{"z_mm", r.z_mm}, {"setup_d_min_um", json_number(r.setup_d_min_um)}});
  const nlohmann::json out = {
      {"bench", "spray"},
      {"session", args.session},
      {"sets", sets},
      {"chain", args.chain},
      {"psf", choices.psf},
      {"results", args.results},
      {"algorithm", setup.options.algorithm},
      {"iterations", setup.options.max_iterations},
      {"grid", {{"n", {grid.nx, grid.ny, grid.nz}}, {"voxel_mm", grid.voxel_size}, {"origin_mm", {grid.origin.x, grid.origin.y, grid.origin.z}}}},
      {"match_mm", match_mm},
      {"relative_peak_threshold", args.detection.relative_peak_threshold},
      {"predicted_limit", limits},
      {"above_limit", above_total.above_limit},
      {"above_limit_detected", above_total.above_detected},
      {"above_limit_detected_fraction",
       json_number(above_total.above_limit ? double(above_total.above_detected) / above_total.above_limit : NAN)},
      {"detections", detections},
      {"unmatched_detections", unmatched_detections},
      {"sets_with_velocity", sets_with_velocity},
      {"size_estimate",
       {{"method", "the diameter whose shadow removes the blob's integrated intensity / shadow_scale, (1 - tau) pi d^2 / 4 "
                   "averaged over the views"},
        {"shadow_scale", json_number(scale > 0 ? scale : NAN)},
        {"shadow_scale_source", args.shadow_scale > 0 ? "--shadow-scale" : "fitted on this session's truth"},
        {"columns", estimated_columns(args.classes_um)},
        {"confusion", confusion},
        {"matched", matched},
        {"same_class_fraction", json_number(matched ? double(same_class) / matched : NAN)},
        {"within_one_class_fraction", json_number(matched ? double(within_one) / matched : NAN)},
        {"blobs_by_estimated_class", blobs_by_estimate}}},
      {"classes", classes_json},
      {"machine", machine_json()}};
  if (args.json_out.empty() || args.json_out == "-") {
    write_json(out, "");
    return;
  }
  write_json(out, args.json_out);
  fmt::print("detected fraction [%] by droplet diameter (truth) and depth; in brackets: above the predicted limit\n");
  fmt::print("{:>10}", "d [um]");
  for (int b = 0; b < args.depth_bins; ++b)
    fmt::print(" {:>15}", fmt::format("z {:.1f}..{:.1f}", z_lo + b * (z_hi - z_lo) / args.depth_bins,
                                      z_lo + (b + 1) * (z_hi - z_lo) / args.depth_bins));
  fmt::print(" {:>15} {:>8} {:>9}\n", "all", "d_eq um", "n (v)");
  for (std::size_t c = 0; c < classes; ++c) {
    const ClassFigures& f = figures[c];
    fmt::print("{:>10}", class_name(args.classes_um, c));
    for (const Cell& cell : f.depth)
      fmt::print(" {:>15}", fmt::format("{} ({})", percent(cell.detected, cell.truth), percent(cell.above_detected, cell.above_limit)));
    fmt::print(" {:>15} {:>8.1f} {:>9}\n",
               fmt::format("{} ({})", percent(f.all.detected, f.all.truth), percent(f.all.above_detected, f.all.above_limit)),
               f.all.detected ? f.d_eq_sum_um / f.all.detected : NAN, fmt::format("{} ({})", f.all.truth, f.velocity_n));
  }
  fmt::print("above the predicted limit: {} of {} detected ({} %); {} blobs, {} unmatched\n", above_total.above_detected,
             above_total.above_limit, percent(above_total.above_detected, above_total.above_limit), detections,
             unmatched_detections);
  fmt::print("size class estimated from each blob's intensity (rows: truth class, columns: estimated; matched droplets)\n{:>10}",
             "d [um]");
  const std::vector<std::string> columns = estimated_columns(args.classes_um);
  for (const std::string& c : columns) fmt::print(" {:>7}", c);
  fmt::print(" {:>8} {:>8}\n", "same %", "d_est um");
  for (std::size_t c = 0; c < classes; ++c) {
    const ClassFigures& f = figures[c];
    fmt::print("{:>10}", class_name(args.classes_um, c));
    for (const int n : f.estimated) fmt::print(" {:>7}", n);
    fmt::print(" {:>8} {:>8.1f}\n", percent(f.estimated[c + 1], f.all.detected),
               f.all.detected ? f.d_est_sum_um / f.all.detected : NAN);
  }
  fmt::print("estimated class = truth class for {} of {} matched droplets ({} %), within one class {} %; shadow scale "
             "{:.4g} ({})\n",
             same_class, matched, percent(same_class, matched), percent(within_one, matched), scale,
             args.shadow_scale > 0 ? "--shadow-scale" : "fitted on this session's truth: pass it as --shadow-scale "
                                                        "for sessions of the same rig, chain and grid");
  if (sets_with_velocity > 0) {
    fmt::print("velocity RMS error against truth [m/s] (3-D correlation at each droplet above the limit)\n{:>10} {:>6} {:>9} {:>7} {:>7} {:>7} {:>7}\n",
               "d [um]", "n", "speed", "u", "v", "w", "|e|");
    for (std::size_t c = 0; c < classes; ++c) {
      const ClassFigures& f = figures[c];
      const double nv = f.velocity_n;
      if (nv == 0) continue;
      fmt::print("{:>10} {:>6} {:>9.2f} {:>7.2f} {:>7.2f} {:>7.2f} {:>7.2f}\n", class_name(args.classes_um, c), f.velocity_n,
                 f.speed_sum / nv, std::sqrt(f.velocity_sq.x / nv), std::sqrt(f.velocity_sq.y / nv),
                 std::sqrt(f.velocity_sq.z / nv), std::sqrt((f.velocity_sq.x + f.velocity_sq.y + f.velocity_sq.z) / nv));
    }
  }
  fmt::print("wrote {}\n", args.json_out);
}

}  // namespace

void add_bench_spray_command(CLI::App& bench) {
  auto args = std::make_shared<BenchSprayArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "spray", "Droplet accuracy on a spray-thesis session: detected fraction by size class and depth against the "
               "predicted visibility limit, and (--results) velocity RMS per size class against the truth");
  cmd->add_option("session", args->session, "spray-thesis session (.h5) with truth")->required();
  cmd->add_option("--calib", args->calib, "Calibration file, or 'truth' (default: the truth)");
  cmd->add_option("--chain", args->chain, "Preprocessing chain for the detection: a preset (shadow-detect, shadow-a, shadow-b) or a chain TOML")
      ->capture_default_str();
  cmd->add_option("--results", args->results,
                  "Results file of 'tomorig process' on the same session (with the same --chain, --psf and --grid): "
                  "droplet velocities from its 3-D correlation");
  pipeline::add_reconstruction_flags(*cmd, args->recon, "ment");
  cmd->add_option("--sets", args->sets, "Sets to judge (N, A:B or a list); default all");
  cmd->add_option("--classes", args->classes_um, "Size-class edges, um (truth diameter)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--depth-bins", args->depth_bins, "Depth bins over the grid's z extent")->capture_default_str();
  cmd->add_option("--match-voxels", args->match_voxels, "A blob matches a droplet within this distance, voxels")
      ->capture_default_str();
  cmd->add_option("--peak-threshold", args->detection.relative_peak_threshold,
                  "A blob's peak must exceed this fraction of the volume's brightest voxel (0: every local maximum)")
      ->capture_default_str();
  cmd->add_option("--shadow-scale", args->shadow_scale,
                  "A blob's integrated intensity per pixel of light its droplet removed, for each blob's size class "
                  "(default: fitted on this session's truth and reported, to pass on for other sessions)");
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json) and print the tables; '-' or none: JSON on stdout")
      ->expected(0, 1);
  cmd->footer("--psf defaults to 'truth' (the session's simulated PSF); the predicted limit uses the same optics.");
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
