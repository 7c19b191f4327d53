// Preview volume: binned images, a coarse grid, MLOS or MENT, projections and the depth profile.
#include "tomorig/processing/quicklook/preview_volume.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "binned_camera.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/display.h"
#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::quicklook {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Without a background level from the caller: this percentile of the binned image. Particle
// images cover far less than a tenth of a frame seeded for tomography (Ns < 0.3), so it is
// background plus a little noise, which MLOS's threshold then ignores.
constexpr double kBackgroundPercentile = 0.10;

// A slice enters the depth profile only if every camera sees this fraction of its voxels.
constexpr double kMinSliceCoverage = 0.05;

// The preview grid: the rig grid's centre, voxels `b` times larger, `depth` times deeper.
VoxelGrid preview_grid(const VoxelGrid& rig, int b, double depth) {
  const Vec3d centre = rig.centre_of((rig.nx - 1) * 0.5, (rig.ny - 1) * 0.5, (rig.nz - 1) * 0.5);
  const int nx = std::max(1, (rig.nx + b - 1) / b);
  const int ny = std::max(1, (rig.ny + b - 1) / b);
  const int nz = std::max(1, static_cast<int>(std::lround(rig.nz * depth / b)));
  VoxelGrid g = VoxelGrid::centred(nx, ny, nz, rig.voxel_size * b);
  g.origin = {g.origin.x + centre.x, g.origin.y + centre.y, g.origin.z + centre.z};
  return g;
}

// Sums b x b blocks of `in` into `out` (floor(W / b) x floor(H / b)), minus b^2 `background`
// per block, clipped at 0.
template <typename T>
void bin_image(const Image& in, int b, double background, Image& out) {
  const int w = out.width(), h = out.height();
  const float offset = static_cast<float>(background * b * b);
  for (int y = 0; y < h; ++y) {
    float* o = out.row<float>(y);
    std::fill(o, o + w, -offset);
    for (int dy = 0; dy < b; ++dy) {
      const T* r = in.row<T>(y * b + dy);
      for (int x = 0; x < w; ++x) {
        float s = 0;
        for (int dx = 0; dx < b; ++dx) s += static_cast<float>(r[x * b + dx]);
        o[x] += s;
      }
    }
    for (int x = 0; x < w; ++x) o[x] = std::max(o[x], 0.0f);
  }
}

void bin_image(const Image& in, int b, double background, Image& out) {
  switch (in.type()) {
    case SampleType::u8: bin_image<std::uint8_t>(in, b, background, out); break;
    case SampleType::u16: bin_image<std::uint16_t>(in, b, background, out); break;
    case SampleType::f32: bin_image<float>(in, b, background, out); break;
  }
}

// The per-pixel level of `binned` (block sums, nothing subtracted) at kBackgroundPercentile.
double low_percentile_per_pixel(const Image& binned, int b, std::vector<float>& scratch) {
  scratch.clear();
  for (int y = 0; y < binned.height(); ++y) {
    const float* r = binned.row<float>(y);
    scratch.insert(scratch.end(), r, r + binned.width());
  }
  if (scratch.empty()) return 0;
  const auto at = scratch.begin() + static_cast<std::ptrdiff_t>(kBackgroundPercentile * (scratch.size() - 1));
  std::nth_element(scratch.begin(), at, scratch.end());
  return *at / (b * b);
}

}  // namespace

void PreviewVolumeOptions::validate() const {
  if (algorithm != "mlos" && algorithm != "ment")
    throw bad_input(fmt::format("preview algorithm '{}' is not available: use mlos or ment", algorithm));
  if (ment_iterations < 1 || ment_iterations > 20)
    throw bad_input(fmt::format("preview ment_iterations = {} is out of range: use 1 to 20", ment_iterations));
  if (binning < 1 || binning > 8)
    throw bad_input(fmt::format("preview binning = {} is out of range: use 1 to 8 pixels", binning));
  if (!(depth_factor >= 1.0 && depth_factor <= 10.0))
    throw bad_input(fmt::format("preview depth_factor = {} is out of range: use 1 to 10 (times the rig grid's depth)",
                                depth_factor));
  if (!(mlos_threshold >= 0.0 && mlos_threshold < 1.0))
    throw bad_input(fmt::format("preview mlos_threshold = {} is out of range: use [0, 1)", mlos_threshold));
  if (!(sigma_px > 0.0 && sigma_px <= 10.0))
    throw bad_input(fmt::format("preview sigma_px = {} is out of range: use (0, 10] binned pixels", sigma_px));
  if (threads < 0 || threads > 256)
    throw bad_input(fmt::format("preview threads = {} is out of range: use 0 (all cores) to 256", threads));
}

struct PreviewVolume::Work {
  std::vector<std::shared_ptr<const calibration::CameraModel>> binned;  // one per camera
  std::vector<calibration::ImageSize> full_sizes;
  VoxelGrid grid;
  VoxelGrid rig_grid;
  bool cameras_at_low_z = true;
  // Per row (j, k): the voxels i in [first, last] that every camera sees (first > last: none).
  std::vector<std::int32_t> first, last;
  std::vector<double> slice_voxels;  // seen voxels per slice

  std::unique_ptr<recon::Reconstructor> reconstructor;
  recon::ReconstructionInput input;
  std::vector<float> scratch;
  std::vector<double> slice_sum;
};

namespace {

// Which voxels of each row every camera sees: their centre lands inside every binned image
// (a voxel outside some image is never active, and would only dilute the profile). A camera
// sees a straight row as a run of voxels, found by sampling every 8th voxel and refining the
// ends voxel by voxel.
void find_visible_rows(const std::vector<std::shared_ptr<const calibration::CameraModel>>& cameras,
                       const std::vector<calibration::ImageSize>& sizes, const VoxelGrid& g,
                       std::vector<std::int32_t>& first, std::vector<std::int32_t>& last, int threads) {
  const std::size_t rows = static_cast<std::size_t>(g.ny) * g.nz;
  first.assign(rows, 0);
  last.assign(rows, g.nx - 1);
  constexpr int kStep = 8;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16)
  for (std::ptrdiff_t r = 0; r < static_cast<std::ptrdiff_t>(rows); ++r) {
    const int j = static_cast<int>(r % g.ny), k = static_cast<int>(r / g.ny);
    int lo = first[r], hi = last[r];
    for (std::size_t c = 0; c < cameras.size() && lo <= hi; ++c) {
      auto sees = [&](int i) {
        const Vec2d p = cameras[c]->project(g.centre_of(i, j, k));
        return std::isfinite(p.x) && std::isfinite(p.y) && p.x >= 0 && p.y >= 0 && p.x <= sizes[c].width - 1 &&
               p.y <= sizes[c].height - 1;
      };
      int a = -1, z = -1;  // first and last sampled voxel seen, within [lo, hi]
      for (int i = lo;; i = std::min(i + kStep, hi)) {
        if (sees(i)) {
          if (a < 0) a = i;
          z = i;
        }
        if (i == hi) break;
      }
      if (a < 0) {
        lo = 1;
        hi = 0;
        break;
      }
      while (a > lo && sees(a - 1)) --a;
      while (z < hi && sees(z + 1)) ++z;
      lo = a;
      hi = z;
    }
    first[r] = lo;
    last[r] = hi;
  }
}

}  // namespace

PreviewVolume::PreviewVolume(std::vector<std::shared_ptr<const calibration::CameraModel>> cameras,
                             std::vector<calibration::ImageSize> sizes, const VoxelGrid& rig_grid,
                             const PreviewVolumeOptions& options)
    : options_(options), work_(std::make_unique<Work>()) {
  options_.validate();
  if (cameras.empty()) throw bad_input("a preview volume needs at least one camera");
  if (sizes.size() != cameras.size())
    throw bad_input(fmt::format("a preview volume got {} cameras but {} image sizes", cameras.size(), sizes.size()));
  if (rig_grid.nx < 1 || rig_grid.ny < 1 || rig_grid.nz < 1 || !(rig_grid.voxel_size > 0))
    throw bad_input("a preview volume needs a voxel grid with at least one voxel of positive size");
  Work& w = *work_;
  const int b = options_.binning;
  w.rig_grid = rig_grid;
  w.grid = preview_grid(rig_grid, b, options_.depth_factor);
  w.full_sizes = sizes;
  std::vector<calibration::ImageSize> binned_sizes;
  double towards_high_z = 0;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    if (!cameras[c]) throw bad_input(fmt::format("preview volume: camera {} has no model", c));
    if (sizes[c].width < b || sizes[c].height < b)
      throw bad_input(fmt::format("preview volume: camera {} images of {} x {} px are smaller than one {} x {} bin",
                                  c, sizes[c].width, sizes[c].height, b, b));
    const Ray centre = cameras[c]->line_of_sight({(sizes[c].width - 1) * 0.5, (sizes[c].height - 1) * 0.5});
    towards_high_z += centre.direction.z;
    w.binned.push_back(std::make_shared<detail::BinnedCamera>(cameras[c], b));
    binned_sizes.push_back({sizes[c].width / b, sizes[c].height / b});
    w.input.sensor_sizes.push_back({sizes[c].width / b, sizes[c].height / b});
  }
  // Lines of sight run from the cameras into the volume: looking towards +z, they stand at low z.
  w.cameras_at_low_z = towards_high_z >= 0;

  find_visible_rows(w.binned, binned_sizes, w.grid, w.first, w.last, options_.threads > 0 ? options_.threads : 1);
  w.slice_voxels.assign(static_cast<std::size_t>(w.grid.nz), 0.0);
  bool seen = false;
  for (std::size_t r = 0; r < w.first.size(); ++r)
    if (w.first[r] <= w.last[r]) {
      w.slice_voxels[r / static_cast<std::size_t>(w.grid.ny)] += w.last[r] - w.first[r] + 1;
      seen = true;
    }
  if (!seen)
    throw bad_input("preview volume: no voxel of the grid is seen by every camera; check the calibration and the "
                    "[grid] of the rig file");

  recon::ReconstructionOptions ro;
  ro.algorithm = options_.algorithm;
  ro.max_iterations = options_.ment_iterations;
  ro.mlos_threshold = options_.mlos_threshold;
  ro.threads = options_.threads;
  w.reconstructor = recon::make_reconstructor(ro);
  for (const auto& m : w.binned) w.input.cameras.push_back(m.get());
  w.input.grid = w.grid;
  w.input.psf.assign(cameras.size(), recon::PsfModel::constant(options_.sigma_px));
  for (std::size_t c = 0; c < cameras.size(); ++c)
    w.input.images.push_back(Image::allocate(binned_sizes[c].width, binned_sizes[c].height, SampleType::f32));
}

PreviewVolume::~PreviewVolume() = default;
PreviewVolume::PreviewVolume(PreviewVolume&&) noexcept = default;
PreviewVolume& PreviewVolume::operator=(PreviewVolume&&) noexcept = default;

const VoxelGrid& PreviewVolume::grid() const { return work_->grid; }

void PreviewVolume::reconstruct(std::span<const Image> images, PreviewResult& out, std::span<const double> backgrounds) {
  const auto start = Clock::now();
  Work& w = *work_;
  const std::size_t cameras = w.binned.size();
  if (images.size() != cameras)
    throw bad_input(fmt::format("preview volume: got {} images for {} cameras", images.size(), cameras));
  if (!backgrounds.empty() && backgrounds.size() != cameras)
    throw bad_input(fmt::format("preview volume: got {} background levels for {} cameras", backgrounds.size(), cameras));
  const int b = options_.binning;
  for (std::size_t c = 0; c < cameras; ++c) {
    const Image& image = images[c];
    if (image.empty())
      throw bad_input(fmt::format("preview volume: camera {} has no image in this set", c));
    if (image.width() != w.full_sizes[c].width || image.height() != w.full_sizes[c].height)
      throw bad_input(fmt::format("preview volume: camera {} image is {} x {} but its calibration is for {} x {}", c,
                                  image.width(), image.height(), w.full_sizes[c].width, w.full_sizes[c].height));
    Image& binned = w.input.images[c];
    double background = backgrounds.empty() ? not_measured : backgrounds[c];
    if (!std::isfinite(background)) {
      bin_image(image, b, 0.0, binned);
      background = low_percentile_per_pixel(binned, b, w.scratch);
    }
    bin_image(image, b, background, binned);
  }

  recon::ReconstructionReport report;
  out.volume = w.reconstructor->reconstruct(w.input, report);
  out.reconstruction_seconds = report.seconds;
  out.grid = w.grid;
  out.active_voxels = out.volume.size();
  out.mip_z = max_projection(out.volume, Axis::z);
  out.mip_y = max_projection(out.volume, Axis::y);
  out.mip_x = max_projection(out.volume, Axis::x);

  // Depth profile over the voxels every camera sees.
  const VoxelGrid& g = w.grid;
  w.slice_sum.assign(static_cast<std::size_t>(g.nz), 0.0);
  const std::size_t nx = static_cast<std::size_t>(g.nx), nxy = nx * static_cast<std::size_t>(g.ny);
  for (std::size_t n = 0; n < out.volume.size(); ++n) {
    const std::size_t index = out.volume.index[n];
    const std::size_t k = index / nxy, row = index / nx;  // row = j + ny k
    const auto i = static_cast<std::int32_t>(index % nx);
    if (i >= w.first[row] && i <= w.last[row]) w.slice_sum[k] += out.volume.intensity[n];
  }
  const double min_voxels = kMinSliceCoverage * static_cast<double>(nxy);
  for (std::size_t k = 0; k < w.slice_sum.size(); ++k)
    w.slice_sum[k] = w.slice_voxels[k] >= min_voxels ? w.slice_sum[k] / w.slice_voxels[k] : not_measured;
  SheetAnalysisOptions sheet;
  sheet.cameras_at_low_z = w.cameras_at_low_z;
  sheet.grid_low_z_mm = w.rig_grid.origin.z - 0.5 * w.rig_grid.voxel_size;
  sheet.grid_high_z_mm = w.rig_grid.origin.z + (w.rig_grid.nz - 0.5) * w.rig_grid.voxel_size;
  out.sheet = analyse_depth_profile(w.slice_sum, g.origin.z, g.voxel_size, sheet);
  out.seconds = seconds_since(start);
}

}  // namespace tomorig::quicklook
