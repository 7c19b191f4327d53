#include "tomorig/pipeline/mean_volume.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/core/set_selection.h"
#include "tomorig/pipeline/exposure_images.h"
#include "tomorig/pipeline/report_json.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/processing/reconstruction/smoothing.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/output_path.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/volume_file.h"

namespace tomorig::pipeline {
namespace {

constexpr int kDepthSlices = 5;  // equidistant x-y slices over the depth, as Fig. 7.12 shows them
// The slices' white: this quantile of the mean's positive voxels. The brightest voxels are a few
// large droplets that happened to sit still, and would leave the rest of the spray black.
constexpr double kWhiteQuantile = 0.995;

float white_level(const DenseVolume& v) {
  std::vector<float> positive;
  for (const float x : v.values)
    if (x > 0) positive.push_back(x);
  if (positive.empty()) return 0;
  const auto at = positive.begin() + static_cast<std::ptrdiff_t>(kWhiteQuantile * static_cast<double>(positive.size() - 1));
  std::nth_element(positive.begin(), at, positive.end());
  return *at;
}

// One slice of `v` as an 8-bit picture, 0 to `top` linear, each voxel a square of `scale`
// pixels (small grids stay visible); `axis` is the normal (0 x, 1 y, 2 z), `at` its index. The
// picture's horizontal axis is x (y for the yz slice), its vertical the remaining one, upwards.
Image slice_image(const DenseVolume& v, int axis, int at, float top) {
  const VoxelGrid& g = v.grid;
  const int w = axis == 0 ? g.ny : g.nx, h = axis == 2 ? g.ny : g.nz;
  const int scale = std::max(1, 512 / std::max(w, h));
  Image out = Image::allocate(w * scale, h * scale, SampleType::u8);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const float value = axis == 0 ? v.at(at, c, r) : axis == 1 ? v.at(c, at, r) : v.at(c, r, at);
      const auto grey =
          static_cast<std::uint8_t>(std::lround(std::clamp(top > 0 ? value / top : 0.0f, 0.0f, 1.0f) * 255.0f));
      for (int dy = 0; dy < scale; ++dy) {
        std::uint8_t* row = out.row<std::uint8_t>((h - 1 - r) * scale + dy);
        std::fill(row + c * scale, row + (c + 1) * scale, grey);
      }
    }
  return out;
}

struct SliceSpec {
  std::string name;
  int axis, index;
};

std::vector<SliceSpec> slice_specs(const VoxelGrid& g) {
  std::vector<SliceSpec> specs{{"mean_yz.png", 0, -1}, {"mean_xz.png", 1, -1}, {"mean_xy.png", 2, -1}};
  for (int s = 0; s < kDepthSlices; ++s)
    specs.push_back({fmt::format("mean_z{}.png", s), 2,
                     static_cast<int>(std::lround((s + 0.5) * g.nz / kDepthSlices - 0.5))});
  return specs;
}

}  // namespace

MeanVolumeReport write_mean_volume(const MeanVolumeOptions& o, const std::function<void(int, int)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (o.exposures.empty()) throw bad_input("the mean volume needs at least one exposure");
  if (!o.smooth.empty() && o.smooth.size() != 3) throw bad_input("--smooth takes three sigmas x,y,z in voxels");
  const storage::SessionReader session(o.session);
  const SessionDescription description = describe_session(session);
  const SessionCameras cameras = session_cameras(description, o.calib);
  ReconstructionSetup setup = reconstruction_setup(description, cameras, o.recon);
  recon::ReconstructionInput& input = setup.input;
  const VoxelGrid& grid = input.grid;
  MeanVolumeReport report;
  report.sets = (o.sets.empty() ? SetSelection() : SetSelection::parse(o.sets)).indices(session.set_count());
  if (report.sets.empty())
    throw bad_input(fmt::format("session '{}' has no sets{} to average: nothing was written", o.session.string(),
                                o.sets.empty() ? "" : fmt::format(" in --sets {}", o.sets)));
  report.grid = grid;
  report.algorithm = setup.options.algorithm;

  // Every output is checked before the first reconstruction (minutes of work).
  std::vector<SliceSpec> slices;
  if (!o.slices.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.slices, ec);
    if (ec || !std::filesystem::is_directory(o.slices))
      throw bad_input(fmt::format("cannot create the slice folder '{}': {}; choose another --slices", o.slices.string(),
                                  ec ? ec.message() : "it is not a folder"));
    slices = slice_specs(grid);
    for (const SliceSpec& s : slices) storage::check_output_path(o.slices / s.name, o.overwrite, "slice picture");
  }
  const nlohmann::json parameters = {{"statistic", "mean"},
                                     {"sets", report.sets},
                                     {"exposures", o.exposures.size() == 2 ? "both" : o.exposures[0] == Exposure::A ? "a" : "b"},
                                     {"chain", o.chain},
                                     {"algorithm", setup.options.algorithm},
                                     {"max_iterations", setup.options.max_iterations},
                                     {"sigma_px", o.recon.psf.empty() ? nlohmann::json(o.recon.sigma_px) : nlohmann::json()},
                                     {"psf", o.recon.psf},
                                     {"smoothing_sigma_voxel", o.smooth},
                                     {"cameras", cameras.source}};
  storage::VolumeFileWriter out(o.out, {o.session.string(), report.sets.front(), parameters.dump()},
                                {.overwrite = o.overwrite, .dense_export = !o.sparse_only});

  const auto reconstructor = recon::make_reconstructor(setup.options);
  SessionPreprocessor preprocessor(session, o.chain);
  std::vector<double> sum(grid.voxel_count(), 0.0);  // double: hundreds of sets add up exactly enough
  const int total = static_cast<int>(report.sets.size() * o.exposures.size());
  for (const std::uint64_t k : report.sets) {
    FrameSet set = session.read_set(k);
    preprocessor.apply(set);
    for (const Exposure e : o.exposures) {
      input.images = exposure_images(set, e, o.session.string(), k,
                                     "leave the set out with --sets or average one exposure with --exposure");
      recon::ReconstructionReport rr;
      SparseVolume v = reconstructor->reconstruct(input, rr);
      if (!o.smooth.empty()) v = recon::gaussian_smooth(v, {o.smooth[0], o.smooth[1], o.smooth[2]}, o.recon.options.threads);
      for (std::size_t n = 0; n < v.size(); ++n) sum[v.index[n]] += v.intensity[n];
      ++report.volumes;
      if (progress) progress(report.volumes, total);
    }
  }
  DenseVolume mean(grid);
  double all = 0;
  for (std::size_t n = 0; n < sum.size(); ++n) {
    mean.values[n] = static_cast<float>(sum[n] / report.volumes);
    all += mean.values[n];
  }
  report.mean_intensity = all / static_cast<double>(std::max<std::size_t>(1, sum.size()));
  report.moments = quality::intensity_moments(mean);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.add("mean", mean, {setup.options.algorithm, parameters.at("exposures").get<std::string>(), to_json(report).dump()});
  out.finish();

  const Vec3d c = grid.voxel_of(report.moments.centroid_mm);
  const int through[3] = {std::clamp(static_cast<int>(std::lround(c.x)), 0, grid.nx - 1),
                          std::clamp(static_cast<int>(std::lround(c.y)), 0, grid.ny - 1),
                          std::clamp(static_cast<int>(std::lround(c.z)), 0, grid.nz - 1)};
  const float white = slices.empty() ? 0.0f : white_level(mean);
  for (const SliceSpec& s : slices) {
    const std::filesystem::path file = o.slices / s.name;
    storage::write_png(file, slice_image(mean, s.axis, s.index >= 0 ? s.index : through[s.axis], white));
    report.slice_files.push_back(file);
  }
  return report;
}

nlohmann::json to_json(const MeanVolumeReport& r) {
  const auto vec = [](const Vec3d& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json files = nlohmann::json::array();
  for (const auto& f : r.slice_files) files.push_back(f.string());
  return {{"sets", r.sets},
          {"volumes", r.volumes},
          {"algorithm", r.algorithm},
          {"grid", {{"n", {r.grid.nx, r.grid.ny, r.grid.nz}},
                    {"voxel_mm", r.grid.voxel_size},
                    {"origin_mm", vec(r.grid.origin)}}},
          {"mass", r.moments.mass},
          {"max", r.moments.max},
          {"mean_intensity", r.mean_intensity},
          {"centroid_mm", vec(r.moments.centroid_mm)},
          {"median_mm", vec(r.moments.median_mm)},
          {"extent_mm", {{"low", vec(r.moments.low_mm)}, {"high", vec(r.moments.high_mm)}, {"tail", 0.05}}},
          {"slices", files},
          {"seconds", r.seconds}};
}

}  // namespace tomorig::pipeline
