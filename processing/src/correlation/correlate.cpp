#include "tomorig/processing/correlation/correlate.h"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>

#include <fmt/core.h>

#include "correlation/direct_correlator.h"
#include "correlation/fft_correlator.h"
#include "correlation/predictor_filters.h"
#include "correlation/volume_deformation.h"
#include "correlation/window_lag_sums.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/correlation/vector_validation.h"

namespace tomorig::piv {
namespace {

using detail::Int3;
using detail::VolumeView;

// The pair of volumes at one binning factor, with B-spline coefficients and support masks made
// on demand (once per correlation, reused by every pass at this factor).
struct Level {
  std::vector<float> a, b;              // binned samples (unused for factor 1: the inputs are used)
  VolumeView view_a, view_b;            // data null: not made yet in this correlation
  bool prefiltered = false, supported = false;
  float largest_a = -1, largest_b = -1;  // largest magnitudes of the samples; negative: not found yet
  std::vector<float> coef_a, coef_b;    // cubic B-spline coefficients, valid if prefiltered
  std::vector<float> deformed_a, deformed_b;
  std::vector<std::uint8_t> support_a, support_b;  // signal_support of a and b, valid if supported
  std::vector<std::uint8_t> support_scratch;
  detail::OccupiedVoxels occupied_a, occupied_b;   // of the deformed pair, memory reused by each pass
  detail::WindowLagSums lag_sums;                  // a direct pass's per-window sums, memory reused
  detail::FaceProducts face_products;              // a direct pass's shell products, memory reused
};

// The buffers of a correlation, kept by the calling thread from one correlation to the next
// (the back-end correlates every set of a run on the same thread): hundreds of megabytes of
// coefficients, deformed volumes and masks are allocated, and their pages faulted in and
// zeroed by the kernel, once per run instead of once per set. Only the memory is kept; every
// correlation recomputes its contents.
std::map<int, Level>& thread_levels() {
  thread_local std::map<int, Level> levels;
  for (auto& [factor, level] : levels) {
    level.view_a = level.view_b = {};
    level.prefiltered = level.supported = false;
    level.largest_a = level.largest_b = -1;
  }
  return levels;
}

// Where the windows of a pass sit, in voxels of its (binned) level.
struct PassGeometry {
  Int3 window, step, nodes;
  int factor = 1;
  // Full-grid voxel coordinate of node n's centre along an axis.
  double centre(int n, int step_axis, int window_axis) const {
    return factor * (n * step_axis + 0.5 * (window_axis - 1)) + 0.5 * (factor - 1);
  }
};

PassGeometry geometry_of(const CorrelationPass& pass, const VolumeView& level) {
  PassGeometry g;
  g.factor = pass.downsample;
  g.window = {pass.window.x / g.factor, pass.window.y / g.factor, pass.window.z / g.factor};
  auto step = [&](int w) { return std::max(1, static_cast<int>(std::lround(w * (1.0 - pass.overlap)))); };
  g.step = {step(g.window.x), step(g.window.y), step(g.window.z)};
  g.nodes = {(level.nx - g.window.x) / g.step.x + 1, (level.ny - g.window.y) / g.step.y + 1,
             (level.nz - g.window.z) / g.step.z + 1};
  return g;
}

// Above these mean fractions of occupied voxels in the pair, the direct correlation costs more
// than the FFTs of the windows; deterministic, so every process picks the same method. Measured
// per kind of pass on the tpiv-thesis FMART pairs (docs/correlation.md, "Speed", sixth round):
//   a deformation pass (every window's lag sums from one shared contraction) at 8.9 % and 14.5 %
//   occupancy took 2.1 and 2.8 s against the FFT's 6.7 and 8.0 s; its cost grows slowly with
//   the occupancy, so up to a quarter occupied it stays well below the FFT's;
//   a pass without deformation (each window searched on its own around the binned peak) at
//   8.9 % took 1.25 s against the FFT's 1.13 s: the break-even is near 8 %.
constexpr double kDirectMaxOccupancyDeformation = 0.25;
constexpr double kDirectMaxOccupancyPreSearch = 0.08;

bool use_direct(const CorrelationPass& pass, bool deform, double occupancy) {
  return pass.method == CorrelationMethod::direct ||
         occupancy <= (deform ? kDirectMaxOccupancyDeformation : kDirectMaxOccupancyPreSearch);
}

// Whether a pass can correlate directly at all: a deformation pass needs windows of 8 voxels
// (its lags +-2 must not reach the wrap); a pass without deformation finds its lags by the
// binned pre-search, so its windows must halve into windows of at least 8.
bool direct_possible(const CorrelationPass& pass, const PassGeometry& g, bool deform) {
  if (pass.method == CorrelationMethod::fft) return false;
  if (deform) return g.window.x >= 8 && g.window.y >= 8 && g.window.z >= 8;
  return g.factor == 1 && g.window.x % 2 == 0 && g.window.y % 2 == 0 && g.window.z % 2 == 0 && g.window.x >= 16 &&
         g.window.y >= 16 && g.window.z >= 16;
}

bool same_grid(const VoxelGrid& a, const VoxelGrid& b) {
  return a.nx == b.nx && a.ny == b.ny && a.nz == b.nz && a.voxel_size == b.voxel_size && a.origin.x == b.origin.x &&
         a.origin.y == b.origin.y && a.origin.z == b.origin.z;
}

int floor_half(int v) { return static_cast<int>(std::floor(v / 2.0)); }

// `sparse` as a dense volume in `out`, reusing out's memory.
void densify(const SparseVolume& sparse, DenseVolume& out) {
  out.grid = sparse.grid;
  out.values.assign(sparse.grid.voxel_count(), 0.0f);
  for (std::size_t n = 0; n < sparse.index.size(); ++n) out.values[sparse.index[n]] = sparse.intensity[n];
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

double CorrelationReport::valid_fraction() const {
  const std::size_t total = valid + replaced + invalid;
  return total ? static_cast<double>(valid) / static_cast<double>(total) : 0.0;
}

VectorField correlate(const DenseVolume& a, const DenseVolume& b, const CorrelationOptions& options,
                      CorrelationReport& report) {
  const auto start_total = std::chrono::steady_clock::now();
  if (!same_grid(a.grid, b.grid))
    throw bad_input(fmt::format("correlation: the volumes lie on different grids ({} x {} x {} and {} x {} x {} voxels, "
                                "voxel size {} and {} mm); reconstruct both exposures on the same grid",
                                a.grid.nx, a.grid.ny, a.grid.nz, b.grid.nx, b.grid.ny, b.grid.nz, a.grid.voxel_size,
                                b.grid.voxel_size));
  options.validate(a.grid);
  if (a.values.size() != a.grid.voxel_count() || b.values.size() != b.grid.voxel_count())
    throw bad_input("correlation: a volume holds fewer values than its grid has voxels");
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  report = {};

  std::map<int, Level>& levels = thread_levels();
  auto level_for = [&](int factor) -> Level& {
    Level& level = levels[factor];
    if (level.view_a.data) return level;
    const VolumeView full_a{a.values.data(), a.grid.nx, a.grid.ny, a.grid.nz};
    const VolumeView full_b{b.values.data(), b.grid.nx, b.grid.ny, b.grid.nz};
    if (factor == 1) {
      level.view_a = full_a;
      level.view_b = full_b;
    } else {
      detail::downsample_sum(full_a, factor, threads, level.a);
      detail::downsample_sum(full_b, factor, threads, level.b);
      level.view_a = {level.a.data(), a.grid.nx / factor, a.grid.ny / factor, a.grid.nz / factor};
      level.view_b = {level.b.data(), a.grid.nx / factor, a.grid.ny / factor, a.grid.nz / factor};
    }
    return level;
  };

  VectorField predictor;  // voxel units: origin/spacing in full-grid voxel coordinates
  bool have_predictor = false;
  VectorField field;
  for (std::size_t p = 0; p < options.passes.size(); ++p) {
    const auto start_pass = std::chrono::steady_clock::now();
    PassReport pr;
    const CorrelationPass& pass = options.passes[p];
    Level& level = level_for(pass.downsample);
    const PassGeometry g = geometry_of(pass, level.view_a);
    const bool deform = pass.deformation && have_predictor;

    VolumeView va = level.view_a, vb = level.view_b;
    // The largest magnitudes of the level's samples, found once per level when first needed
    // (the support masks, the listing of a pass without deformation).
    auto find_largest = [&] {
      if (level.largest_a >= 0) return;
      level.largest_a = detail::largest_magnitude(level.view_a, threads);
      level.largest_b = detail::largest_magnitude(level.view_b, threads);
    };
    // Of va and vb: the samples', or the deformed volumes' as the deformation wrote them.
    float largest_a = -1, largest_b = -1;
    if (deform) {
      if (pass.interpolation == Interpolation::cubic_bspline) {
        if (!level.prefiltered) {
          detail::bspline_coefficients(level.view_a, threads, level.coef_a);
          detail::bspline_coefficients(level.view_b, threads, level.coef_b);
          level.prefiltered = true;
        }
        va.data = level.coef_a.data();
        vb.data = level.coef_b.data();
      }
      // Where the samples have signal: made once per level, reused by every deformation pass.
      if (!level.supported) {
        find_largest();
        detail::signal_support(level.view_a, detail::kSupportThreshold, level.largest_a, detail::kSupportRadius,
                               threads, level.support_a, level.support_scratch);
        detail::signal_support(level.view_b, detail::kSupportThreshold, level.largest_b, detail::kSupportRadius,
                               threads, level.support_b, level.support_scratch);
        level.supported = true;
      }
      const detail::DeformedLargest largest = detail::deform_pair(
          va, vb, predictor, g.factor, pass.interpolation, level.deformed_a, level.deformed_b, threads, level.support_a,
          level.support_b);
      largest_a = largest.a;
      largest_b = largest.b;
      va.data = level.deformed_a.data();
      vb.data = level.deformed_b.data();
    }
    pr.seconds_deformation = seconds_since(start_pass);
    const auto start_windows = std::chrono::steady_clock::now();

    field = VectorField(g.nodes.x, g.nodes.y, g.nodes.z);
    field.origin = {g.centre(0, g.step.x, g.window.x), g.centre(0, g.step.y, g.window.y), g.centre(0, g.step.z, g.window.z)};
    field.spacing = {double(g.factor * g.step.x), double(g.factor * g.step.y), double(g.factor * g.step.z)};

    const detail::FftCorrelator correlator(g.window, options.weighting, options.gaussian_sigma);
    // Sparse direct correlation: the occupied voxels listed once, in blocks of the window step
    // that the overlapping windows share. The deformation passes correlate at the lags around
    // their predictor; the passes without deformation (the single pass, the integer-offset
    // pass) at the lags around the peak of the same windows binned 2x (a pre-search by FFT at
    // an eighth of the voxels), so they find the FFT's peak wherever the binned one finds it
    // within a voxel or two.
    const detail::OccupiedVoxels& occupied_a = level.occupied_a;
    const detail::OccupiedVoxels& occupied_b = level.occupied_b;
    bool direct = false;
    // (Entries store 16-bit coordinates: larger volumes keep the FFT.)
    const bool listable = va.nx <= 65535 && va.ny <= 65535 && va.nz <= 65535;
    double seconds_listing = 0;
    if (listable && direct_possible(pass, g, deform)) {
      const auto start_listing = std::chrono::steady_clock::now();
      if (!deform) {
        find_largest();
        largest_a = level.largest_a;
        largest_b = level.largest_b;
      }
      detail::list_occupied(va, g.step, detail::kOccupiedThreshold, largest_a, threads, level.occupied_a, deform);
      detail::list_occupied(vb, g.step, detail::kOccupiedThreshold, largest_b, threads, level.occupied_b, false);
      seconds_listing = seconds_since(start_listing);
      pr.occupied_fraction = 0.5 * (occupied_a.occupied_fraction + occupied_b.occupied_fraction);
      direct = use_direct(pass, deform, pr.occupied_fraction);
    }
    std::optional<detail::DirectCorrelator> direct_correlator;
    double seconds_lag_sums = 0;
    if (direct) direct_correlator.emplace(g.window, options.weighting, options.gaussian_sigma);
    // The pre-search's binned volumes and windows (passes without deformation).
    std::optional<detail::FftCorrelator> coarse_correlator;
    VolumeView coarse_a, coarse_b;
    if (direct && !deform) {
      const auto start_binning = std::chrono::steady_clock::now();
      Level& coarse = level_for(2);
      coarse_a = coarse.view_a;
      coarse_b = coarse.view_b;
      coarse_correlator.emplace(Int3{g.window.x / 2, g.window.y / 2, g.window.z / 2}, options.weighting,
                                options.gaussian_sigma);
      seconds_listing += seconds_since(start_binning);
    }
    // Windows on block borders share their faces' wrapped products (shell_products.cpp).
    const bool shared_faces =
        direct && deform && g.window.x % g.step.x == 0 && g.window.y % g.step.y == 0 && g.window.z % g.step.z == 0;
    if (direct && deform) {
      // Every window's lag sums at once, shared between the overlapping windows. (The windows
      // of a deformation pass start at node * step, all inside the volumes.)
      const auto start_sums = std::chrono::steady_clock::now();
      detail::window_lag_sums(occupied_a, vb, occupied_b, g.window, g.step, g.nodes,
                              direct_correlator->weights_x(), direct_correlator->weights_y(),
                              direct_correlator->weights_z(), threads, level.lag_sums);
      if (shared_faces) detail::face_products(occupied_a, vb, g.window, threads, level.face_products);
      seconds_lag_sums = seconds_since(start_sums);
    }
    const detail::FaceProducts* face_products = shared_faces ? &level.face_products : nullptr;
    const float* lag_sums = direct && deform ? level.lag_sums.sums.data() : nullptr;
    pr.method = direct ? "direct" : "fft";
    const long long node_count = static_cast<long long>(field.count());
    std::size_t fallbacks = 0, empty = 0, fft_fallbacks = 0;
    double load = 0, correlation = 0, peak_fit = 0;
#pragma omp parallel num_threads(threads) reduction(+ : fallbacks, empty, fft_fallbacks, load, correlation, peak_fit)
    {
      auto scratch = correlator.make_scratch();  // once per thread and pass, never per window
      detail::DirectCorrelator::Scratch direct_scratch;
      std::optional<detail::FftCorrelator::Scratch> coarse_scratch;
      if (coarse_correlator) coarse_scratch = coarse_correlator->make_scratch();
#pragma omp for schedule(dynamic, 4)
      for (long long n = 0; n < node_count; ++n) {
        const int i = static_cast<int>(n % g.nodes.x);
        const int j = static_cast<int>((n / g.nodes.x) % g.nodes.y);
        const int k = static_cast<int>(n / (static_cast<long long>(g.nodes.x) * g.nodes.y));
        const Int3 start{i * g.step.x, j * g.step.y, k * g.step.z};
        // Predicted displacement at the node, in voxels of this level.
        Vec3f predicted{};
        if (have_predictor) {
          const Vec3f d = detail::sample_field(predictor, field.origin.x + i * field.spacing.x,
                                               field.origin.y + j * field.spacing.y, field.origin.z + k * field.spacing.z);
          predicted = {d.x / g.factor, d.y / g.factor, d.z / g.factor};
        }
        Int3 offset{};  // integer displacement between the windows, split symmetrically
        if (have_predictor && !deform)
          offset = {static_cast<int>(std::lround(predicted.x)), static_cast<int>(std::lround(predicted.y)),
                    static_cast<int>(std::lround(predicted.z))};
        const Int3 start_a{start.x - floor_half(offset.x), start.y - floor_half(offset.y), start.z - floor_half(offset.z)};
        const Int3 start_b{start_a.x + offset.x, start_a.y + offset.y, start_a.z + offset.z};
        detail::WindowPeak peak;
        bool by_fft = !direct;
        if (direct && deform) {
          peak = direct_correlator->correlate_from_sums(lag_sums + n * detail::kLagSlots, occupied_a, vb, occupied_b,
                                                        start, direct_scratch, by_fft, face_products);
          fft_fallbacks += by_fft;
        } else if (direct) {
          // The binned windows holding these (a binned voxel k holds voxels 2k and 2k + 1): a
          // displacement D moves the binned particles D / 2, so the binned peak d says the
          // full windows' peak lies near 2 d + 2 (sb - sa) - offset.
          const Int3 sa{floor_half(start_a.x), floor_half(start_a.y), floor_half(start_a.z)};
          const Int3 sb{floor_half(start_b.x), floor_half(start_b.y), floor_half(start_b.z)};
          const detail::WindowPeak coarse = coarse_correlator->correlate(coarse_a, sa, coarse_b, sb, *coarse_scratch);
          by_fft = !coarse.valid;
          if (coarse.valid) {
            const Int3 centre{static_cast<int>(std::lround(2.0 * coarse.dx + 2 * (sb.x - sa.x) - offset.x)),
                              static_cast<int>(std::lround(2.0 * coarse.dy + 2 * (sb.y - sa.y) - offset.y)),
                              static_cast<int>(std::lround(2.0 * coarse.dz + 2 * (sb.z - sa.z) - offset.z))};
            peak = direct_correlator->correlate_around(occupied_a, occupied_b, vb, start_a, start_b, centre,
                                                       direct_scratch, by_fft);
          }
          fft_fallbacks += by_fft;
        }
        if (by_fft) peak = correlator.correlate(va, start_a, vb, start_b, scratch);
        fallbacks += peak.fallbacks;
        empty += peak.empty;
        if (!peak.valid) continue;  // stays invalid with peak 0
        const Vec3f base = deform ? predicted : Vec3f{float(offset.x), float(offset.y), float(offset.z)};
        field.displacement[n] = {(base.x + peak.dx) * g.factor, (base.y + peak.dy) * g.factor, (base.z + peak.dz) * g.factor};
        field.peak[n] = peak.peak;
        field.status[n] = VectorStatus::valid;
      }
      const detail::StageSeconds coarse_seconds = coarse_scratch ? coarse_scratch->seconds : detail::StageSeconds{};
      load += scratch.seconds.load + direct_scratch.seconds.load + coarse_seconds.load;
      correlation += scratch.seconds.correlation + direct_scratch.seconds.correlation + coarse_seconds.correlation;
      peak_fit += scratch.seconds.peak + direct_scratch.seconds.peak + coarse_seconds.peak;
    }
    pr.fft_fallbacks = fft_fallbacks;
    pr.seconds_windows = seconds_since(start_windows);
    // (The occupied-voxel lists and the shared lag sums ran on all threads: their wall time
    // times the threads.)
    pr.thread_seconds_load = load + seconds_listing * threads;
    pr.thread_seconds_correlation = correlation + seconds_lag_sums * threads;
    pr.thread_seconds_peak = peak_fit;
    pr.empty_windows = empty;
    const auto start_validation = std::chrono::steady_clock::now();

    std::vector<std::uint8_t> mask;
    if (options.illumination) {
      mask.resize(field.count());
      for (int k = 0; k < field.nz; ++k)
        for (int j = 0; j < field.ny; ++j)
          for (int i = 0; i < field.nx; ++i) {
            const Vec3d world = a.grid.centre_of(field.origin.x + i * field.spacing.x, field.origin.y + j * field.spacing.y,
                                                 field.origin.z + k * field.spacing.z);
            mask[field.linear(i, j, k)] = options.illumination(world) >= options.min_illumination;
          }
    }
    const ValidationCounts counts = validate_field(field, options, mask);

    pr.nodes_x = field.nx;
    pr.nodes_y = field.ny;
    pr.nodes_z = field.nz;
    pr.low_peak = counts.low_peak;
    pr.too_large = counts.too_large;
    pr.median_outliers = counts.median_outliers;
    pr.replaced = counts.replaced;
    pr.masked = counts.masked;
    pr.peak_fallbacks = fallbacks;

    if (p + 1 < options.passes.size()) {
      predictor = field;
      detail::fill_invalid(predictor);
      if (options.smooth_predictor) detail::smooth_gaussian3(predictor);
      have_predictor = true;
    }
    pr.seconds_validation = seconds_since(start_validation);
    pr.seconds = seconds_since(start_pass);
    report.passes.push_back(pr);
  }

  // Node positions from full-grid voxel coordinates to world mm.
  field.origin = a.grid.centre_of(field.origin.x, field.origin.y, field.origin.z);
  field.spacing = field.spacing * a.grid.voxel_size;
  for (VectorStatus s : field.status) {
    report.valid += s == VectorStatus::valid;
    report.replaced += s == VectorStatus::replaced;
    report.invalid += s == VectorStatus::invalid;
  }
  report.seconds_total = seconds_since(start_total);
  return field;
}

VectorField correlate(const SparseVolume& a, const SparseVolume& b, const CorrelationOptions& options,
                      CorrelationReport& report) {
  if (!same_grid(a.grid, b.grid))
    throw bad_input(fmt::format("correlation: the volumes lie on different grids ({} x {} x {} and {} x {} x {} voxels); "
                                "reconstruct both exposures on the same grid",
                                a.grid.nx, a.grid.ny, a.grid.nz, b.grid.nx, b.grid.ny, b.grid.nz));
  options.validate(a.grid);
  // The dense pair in buffers the calling thread keeps between correlations (the back-end
  // correlates every set on one thread): two fresh volumes of hundreds of megabytes per set
  // cost their page faults and the kernel's zeroing every time (6.8 % of `tomorig process`'s CPU
  // samples); a kept buffer is only cleared.
  thread_local DenseVolume dense_a, dense_b;
  densify(a, dense_a);
  densify(b, dense_b);
  return correlate(dense_a, dense_b, options, report);
}

FftFloor measure_fft_floor(const VoxelGrid& grid, const CorrelationOptions& options) {
  options.validate(grid);
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  FftFloor floor;
  for (const CorrelationPass& pass : options.passes) {
    const int f = pass.downsample;
    const VolumeView level{nullptr, grid.nx / f, grid.ny / f, grid.nz / f};
    const PassGeometry g = geometry_of(pass, level);
    const long long windows = static_cast<long long>(g.nodes.x) * g.nodes.y * g.nodes.z;
    const detail::FftCorrelator correlator(g.window, WindowWeighting::top_hat);
    const auto start = std::chrono::steady_clock::now();
#pragma omp parallel num_threads(threads)
    {
      auto scratch = correlator.make_scratch();
      // Particle-like data (not zeros: FFTW's speed does not depend on the values, but
      // subnormals would), the same in every thread.
      const std::size_t count = static_cast<std::size_t>(g.window.x) * g.window.y * g.window.z;
      std::uint32_t state = 12345u;
      for (std::size_t m = 0; m < count; ++m) {
        state = state * 1664525u + 1013904223u;
        scratch.a.get()[m] = static_cast<float>(state >> 8) * (1.0f / 16777216.0f);
        scratch.b.get()[m] = scratch.a.get()[(m + 7) % count];
      }
#pragma omp for schedule(dynamic, 4)
      for (long long n = 0; n < windows; ++n) correlator.transforms_only(scratch);
    }
    floor.pass_seconds.push_back(seconds_since(start));
    floor.seconds_total += floor.pass_seconds.back();
  }
  return floor;
}

}  // namespace tomorig::piv
