// The dense reference MENT (thesis Sect. 3.1.1, Eqs. 3.1-3.4): the first implementation, kept
// unchanged as the reference the sparse MENT (ment_reconstructor.cpp) is tested against. It
// re-sweeps the whole grid lattice, refined to half a voxel in z, for every camera update, so it
// is slow (~12 s per iteration on tpiv-thesis); use it only on small cases.
//
// Eq. 3.2 sums, for a pixel of camera j, the products of the other cameras' pseudo-images
// along that pixel's line of sight L (the thesis samples it at half the voxel depth; we sample it
// once per voxel depth, see kSubsteps); the
// other cameras' values are read bilinearly where L projects into them, i.e. on the epipolar
// lines. Marching every pixel's ray would need the inverse of every camera model. We compute
// the same sum from the other side: the samples of all lines of sight are the points of the
// grid lattice refined to half a voxel in z, whose image positions the GridProjector gives
// for every camera; each sample adds its product of the other pseudo-images to the pixel of
// camera j it projects into, shared bilinearly (the adjoint of the bilinear read). So one
// sweep over the lattice gives the denominator of Eq. 3.2 for every pixel of camera j at once.
//
// The cameras are updated in turn, each from the latest pseudo-images of the others (Minerbo's
// scheme). Updating all cameras from the same old values is unstable: scaling every h by a
// scales each new h by a^-(N-1), so the overall level would swing and overflow.
//
// A sample only matters if it projects next to a non-empty pixel of every camera (h_j is 0
// where p_j is, Eq. 3.1), so the sweep reads the most selective camera first and stops at the
// first zero, as MLOS does.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <omp.h>

#include "grid_projector.h"
#include "ment_reference.h"
#include "prepared_input.h"
#include "support.h"
#include "system_memory.h"
#include "tomorig/core/error.h"

namespace tomorig::recon {
namespace {
using namespace detail;

// Line-of-sight samples per voxel depth (the thesis's dz_1 = 0.5 dz_2 would be 2). It is also V of
// Eq. 3.2: the sum over samples divided by it is the line integral in voxel units, so that the
// product of Eq. 3.4 needs no further factor.
// One, as the sparse MENT (ment_reconstructor.cpp explains why), so that the two compare.
constexpr int kSubsteps = 1;

// A camera-sized plane with a one-pixel border of zeros: bilinear reads and splats anywhere in
// the image span [-0.5, W - 0.5] need no bounds checks.
struct Plane {
  int width = 0, height = 0, stride = 0;
  std::vector<float> data;

  Plane() = default;
  Plane(int w, int h) : width(w), height(h), stride(w + 2), data(static_cast<std::size_t>(w + 2) * (h + 2), 0.0f) {}

  float& at(int x, int y) { return data[static_cast<std::size_t>(y + 1) * stride + x + 1]; }
  float at(int x, int y) const { return data[static_cast<std::size_t>(y + 1) * stride + x + 1]; }

  // The 2 x 2 neighbourhood of (u, v): offset of its top-left cell and the bilinear fractions;
  // false outside the image span.
  bool cell(float u, float v, std::size_t& offset, float& ax, float& ay) const {
    if (!(u >= -0.5f && u <= width - 0.5f && v >= -0.5f && v <= height - 0.5f)) return false;
    // u, v >= -0.5, so truncating u + 1 floors it without a libm call.
    const int x = static_cast<int>(u + 1.0f), y = static_cast<int>(v + 1.0f);
    ax = u + 1.0f - static_cast<float>(x);
    ay = v + 1.0f - static_cast<float>(y);
    offset = static_cast<std::size_t>(y) * stride + x;
    return true;
  }
  float read(std::size_t offset, float ax, float ay) const {
    const float* p = data.data() + offset;
    const float top = p[0] + ax * (p[1] - p[0]);
    const float bottom = p[stride] + ax * (p[stride + 1] - p[stride]);
    return top + ay * (bottom - top);
  }
  float sample(float u, float v) const {
    std::size_t offset = 0;
    float ax = 0, ay = 0;
    return cell(u, v, offset, ax, ay) ? read(offset, ax, ay) : 0.0f;
  }
  void splat(std::size_t offset, float ax, float ay, float value) {
    float* p = data.data() + offset;
    const float bottom = ay * value, top = value - bottom;
    p[0] += top - ax * top;
    p[1] += ax * top;
    p[stride] += bottom - ax * bottom;
    p[stride + 1] += ax * bottom;
  }
};

// Image positions of one grid row (voxels 0 .. nx-1 of row j) in slice k and k + 1, for every
// camera, and the positions of the sample at depth k + t between them.
class RowPositions {
 public:
  RowPositions(std::size_t cams, int nx)
      : nx_(nx), u0_(cams * nx), v0_(cams * nx), u1_(cams * nx), v1_(cams * nx) {}

  void load(const GridProjector& projector, std::size_t cams, int j, int k, bool next) {
    for (std::size_t c = 0; c < cams; ++c) {
      projector.row(c, j, k, u0_.data() + c * nx_, v0_.data() + c * nx_);
      if (next) projector.row(c, j, k + 1, u1_.data() + c * nx_, v1_.data() + c * nx_);
    }
  }
  float u(std::size_t c, int i, float t) const { return lerp(u0_, u1_, c, i, t); }
  float v(std::size_t c, int i, float t) const { return lerp(v0_, v1_, c, i, t); }

 private:
  float lerp(const std::vector<float>& a, const std::vector<float>& b, std::size_t c, int i, float t) const {
    const std::size_t n = c * nx_ + i;
    return t == 0.0f ? a[n] : a[n] + t * (b[n] - a[n]);
  }
  std::size_t nx_;
  std::vector<float> u0_, v0_, u1_, v1_;
};

struct CameraUpdate {
  double residual_sum = 0.0;  // sum |p - h D / V| over the camera's non-empty pixels
  double intensity_sum = 0.0;  // sum p
  double update_sum = 0.0;     // sum |1 - h_new / h_old|
  std::size_t updated = 0;
};

class DenseMentReconstructor final : public Reconstructor {
 public:
  explicit DenseMentReconstructor(const ReconstructionOptions& options) : options_(options) {}
  std::string name() const override { return "ment-dense-reference"; }

 protected:
  SparseVolume run(const ReconstructionInput& input, ReconstructionReport& report) override {
    in_ = prepare_input(input, options_);
    report.threads = in_.threads;
    const std::size_t cams = in_.camera_count();

    check_memory(report);
    const GridProjector projector(in_);
    make_planes();
    report.setup_seconds = elapsed_seconds();

    for (int it = 1; it <= options_.max_iterations; ++it) {
      const auto t0 = std::chrono::steady_clock::now();
      CameraUpdate total;
      for (std::size_t c = 0; c < cams; ++c) {
        const CameraUpdate u = update_camera(projector, c);
        total.residual_sum += u.residual_sum;
        total.intensity_sum += u.intensity_sum;
        total.update_sum += u.update_sum;
        total.updated += u.updated;
      }
      IterationStats stats;
      stats.iteration = it;
      stats.residual = total.intensity_sum > 0 ? total.residual_sum / total.intensity_sum : 0.0;
      stats.mean_update = total.updated > 0 ? total.update_sum / static_cast<double>(total.updated) : 0.0;
      stats.seconds = seconds_since(t0);
      report.history.push_back(stats);
      report.iterations = it;
      if (options_.stop_mean_update > 0 && stats.mean_update < options_.stop_mean_update) break;
    }

    SparseVolume volume = recover_volume(projector, report);
    report.active_voxels = volume.size();
    in_ = {};
    pseudo_.clear();
    measured_.clear();
    return volume;
  }

 private:
  // Up front: the planes (measured, pseudo, denominator and one accumulator per thread per
  // camera) and an upper bound on the output. A voxel with a non-zero product is non-empty in
  // every camera, so in particular in the most selective one: the output holds at most the
  // fraction of that camera's pixels whose bilinear neighbourhood has a non-empty pixel.
  void check_memory(ReconstructionReport& report) {
    const double fixed = image_bytes(in_, 3 + in_.threads, 1);
    double fraction = 1.0;
    for (const CameraImage& im : in_.images) {
      const float cut = cut_of(im);
      auto lit = [&](int x, int y) { return x >= 0 && y >= 0 && x < im.width && y < im.height && im.at(x, y) >= cut && im.at(x, y) > 0; };
      std::size_t reachable = 0;
      for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) reachable += lit(x, y) || lit(x - 1, y) || lit(x, y - 1) || lit(x - 1, y - 1);
      fraction = std::min(fraction, static_cast<double>(reachable) / static_cast<double>(im.pixels.size()));
    }
    output_budget_fixed_ = fixed;
    const double output = 8.0 * fraction * static_cast<double>(in_.grid.voxel_count());
    report.estimated_memory_mb = (fixed + output) / (1024.0 * 1024.0);
    require_memory(fixed + output, options_.memory_limit_mb,
                   fmt::format("MENT on a grid of {} x {} x {} voxels (up to {:.1f} % of them non-zero)", in_.grid.nx,
                               in_.grid.ny, in_.grid.nz, 100.0 * fraction));
  }

  float cut_of(const CameraImage& im) const { return static_cast<float>(options_.mlos_threshold) * im.max; }

  // p_j thresholded as MLOS does, and h_j^0 of Eq. 3.1: 1 where p_j > 0, else 0.
  void make_planes() {
    measured_.clear();
    pseudo_.clear();
    selectivity_.clear();
    for (const CameraImage& im : in_.images) {
      Plane p(im.width, im.height), h(im.width, im.height);
      const float cut = cut_of(im);
      double lit = 0;
      for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
          const float value = im.at(x, y);
          if (value > 0 && value >= cut) {
            p.at(x, y) = value;
            h.at(x, y) = 1.0f;
            ++lit;
          }
        }
      selectivity_.push_back(lit);
      measured_.push_back(std::move(p));
      pseudo_.push_back(std::move(h));
    }
    order_.resize(in_.camera_count());
    std::iota(order_.begin(), order_.end(), 0);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](std::size_t a, std::size_t b) { return selectivity_[a] < selectivity_[b]; });
  }

  // One MENT step for camera `target` (Eq. 3.2): the denominator from the other cameras'
  // current pseudo-images, then h_target = p_target / denominator.
  CameraUpdate update_camera(const GridProjector& projector, std::size_t target) {
    const VoxelGrid& g = in_.grid;
    const std::size_t cams = in_.camera_count();
    const Plane& mask = measured_[target];
    std::vector<Plane> partial(static_cast<std::size_t>(in_.threads), Plane(mask.width, mask.height));
    std::vector<std::size_t> others;
    for (std::size_t c : order_)
      if (c != target) others.push_back(c);

#pragma omp parallel num_threads(in_.threads)
    {
      Plane& acc = partial[static_cast<std::size_t>(omp_get_thread_num())];
      RowPositions pos(cams, g.nx);
#pragma omp for schedule(dynamic, 1)
      for (int k = 0; k < g.nz; ++k) {
        const bool next = k + 1 < g.nz;
        const int substeps = next ? kSubsteps : 1;
        for (int j = 0; j < g.ny; ++j) {
          pos.load(projector, cams, j, k, next);
          for (int s = 0; s < substeps; ++s) {
            const float t = static_cast<float>(s) / kSubsteps;
            for (int i = 0; i < g.nx; ++i) {
              std::size_t offset = 0;
              float ax = 0, ay = 0;
              if (!mask.cell(pos.u(target, i, t), pos.v(target, i, t), offset, ax, ay)) continue;
              if (!(mask.read(offset, ax, ay) > 0.0f)) continue;
              float product = 1.0f;
              for (std::size_t c : others) {
                product *= pseudo_[c].sample(pos.u(c, i, t), pos.v(c, i, t));
                if (!(product > 0.0f)) break;
              }
              if (product > 0.0f) acc.splat(offset, ax, ay, product);
            }
          }
        }
      }
    }

    Plane& h = pseudo_[target];
    CameraUpdate out;
    for (int y = 0; y < mask.height; ++y)
      for (int x = 0; x < mask.width; ++x) {
        const float p = mask.at(x, y);
        if (!(p > 0.0f)) continue;
        double denominator = 0;
        for (const Plane& a : partial) denominator += a.at(x, y);
        denominator /= kSubsteps;
        const double old = h.at(x, y);
        out.residual_sum += std::fabs(p - old * denominator);
        out.intensity_sum += p;
        const double next = denominator > 0 ? p / denominator : 0.0;
        if (old > 0) {
          out.update_sum += std::fabs(1.0 - next / old);
          ++out.updated;
        }
        h.at(x, y) = static_cast<float>(next);
      }
    return out;
  }

  // Eq. 3.4: E = product of the pseudo-images at the voxel's image positions, slice by slice in
  // z order, appended straight to the sparse output.
  SparseVolume recover_volume(const GridProjector& projector, ReconstructionReport& report) {
    const VoxelGrid& g = in_.grid;
    const std::size_t cams = in_.camera_count();
    SparseVolume volume;
    volume.grid = g;
    const double limit_mb = options_.memory_limit_mb > 0 ? options_.memory_limit_mb : usable_memory_mb();
    const double budget = limit_mb > 0 ? (limit_mb * 1024.0 * 1024.0 - output_budget_fixed_) / 8.0 : 1e300;
    bool over_budget = false;

#pragma omp parallel num_threads(in_.threads)
    {
      RowPositions pos(cams, g.nx);
      std::vector<std::uint32_t> index;
      std::vector<float> value;
#pragma omp for ordered schedule(static, 1)
      for (int k = 0; k < g.nz; ++k) {
        index.clear();
        value.clear();
        for (int j = 0; j < g.ny; ++j) {
          pos.load(projector, cams, j, k, false);
          for (int i = 0; i < g.nx; ++i) {
            float product = 1.0f;
            for (std::size_t c : order_) {
              product *= pseudo_[c].sample(pos.u(c, i, 0.0f), pos.v(c, i, 0.0f));
              if (!(product > 0.0f)) break;
            }
            if (product > 0.0f && std::isfinite(product)) {
              index.push_back(static_cast<std::uint32_t>(g.linear(i, j, k)));
              value.push_back(product);
            }
          }
        }
#pragma omp ordered
        {
          if (!over_budget && static_cast<double>(volume.size() + index.size()) <= budget) {
            volume.index.insert(volume.index.end(), index.begin(), index.end());
            volume.intensity.insert(volume.intensity.end(), value.begin(), value.end());
          } else {
            over_budget = true;
          }
        }
      }
    }
    if (over_budget) {
      const std::string what = fmt::format("the MENT volume (more than {} non-zero voxels)", volume.size());
      require_memory(output_budget_fixed_ + 8.0 * static_cast<double>(volume.size()) * 2.0, limit_mb, what);
      throw bad_input(fmt::format("reconstruction: {} needs more than the {:.0f} MB available", what, limit_mb));
    }
    report.estimated_memory_mb =
        (output_budget_fixed_ + 8.0 * static_cast<double>(volume.size())) / (1024.0 * 1024.0);
    return volume;
  }

  ReconstructionOptions options_;
  PreparedInput in_;
  std::vector<Plane> measured_, pseudo_;
  std::vector<double> selectivity_;
  std::vector<std::size_t> order_;
  double output_budget_fixed_ = 0.0;
};

}  // namespace

std::unique_ptr<Reconstructor> make_ment_dense_reference(const ReconstructionOptions& options) {
  options.validate();
  return std::make_unique<DenseMentReconstructor>(options);
}

}  // namespace tomorig::recon
