// MENT (thesis Sect. 3.1.1, Eqs. 3.1-3.4): see ment.h.
//
// Eq. 3.2 sums, for a pixel of camera j, the products of the other cameras' pseudo-images
// along that pixel's line of sight L (the thesis samples it at half the voxel depth; we sample it
// once per voxel depth, see kSubsteps); the
// other cameras' values are read bilinearly where L projects into them, i.e. on the epipolar
// lines. Marching every pixel's ray would need the inverse of every camera model. We compute
// the same sum from the other side: the samples of all lines of sight are the points of the
// grid lattice (refined in z when kSubsteps > 1); each sample adds its product of the other
// pseudo-images to the pixel of camera j it projects into, shared bilinearly (the adjoint of the
// bilinear read). So one pass over the samples gives the denominator of Eq. 3.2 for every pixel
// of camera j at once.
//
// Only samples next to a non-empty pixel of every camera can contribute (h_j is 0 where p_j is,
// Eq. 3.1). They are found once, before the iterations (ment_samples.h), with their image
// positions packed per camera; each camera update then visits just them: no positions are
// recomputed, no empty lattice point is touched, and nothing is allocated. The dense reference
// (ment_reference.cpp) re-sweeps the whole lattice each time and gives the same result.
//
// The cameras are updated in turn, each from the latest pseudo-images of the others (Minerbo's
// scheme). Updating all cameras from the same old values is unstable: scaling every h by a
// scales each new h by a^-(N-1), so the overall level would swing and overflow.
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
#include "ment.h"
#include "ment_samples.h"
#include "support_scan.h"
#include "prepared_input.h"
#include "support.h"
#include "system_memory.h"
#include "tomorig/core/error.h"

namespace tomorig::recon::detail {
namespace {

// Line-of-sight samples per voxel depth. It is also V of Eq. 3.2: the sum over samples divided
// by it is the line integral in voxel units, so that the product of Eq. 3.4 needs no further
// factor. The thesis sampled at half the voxel depth (dz_1 = 0.5 dz_2); one sample per voxel
// gave the same Q on tpiv-thesis at 0.05 ppp (0.800 against 0.796 with two, 4 iterations; the
// residuals agree to 1e-3) at half the samples, time and memory, so one it is.
// The sample list holds voxel centres only (ment_samples.h).
constexpr int kSubsteps = 1;

struct PlaneRef {
  const float* data;
  std::size_t stride;
  std::size_t camera;
};

// The hot loop of a camera update: for each sample, the product of the other cameras'
// pseudo-images at its positions, splatted into the target camera's accumulator. Fixed > 0
// fixes the number of other cameras at compile time (unrolled); 0 takes `count`.
template <std::size_t Fixed>
void splat_products(const CellCode& codec, const std::uint32_t* code, std::size_t samples, std::size_t cams,
                    const PlaneRef* others, std::size_t count, std::size_t target, float* acc, std::size_t stride) {
  const std::size_t m = Fixed > 0 ? Fixed : count;
  for (std::size_t s = 0; s < samples; ++s, code += cams) {
    float product = 1.0f;
    for (std::size_t o = 0; o < m; ++o) product *= codec.read(others[o].data, others[o].stride, code[others[o].camera]);
    if (product > 0.0f) codec.splat(acc, stride, code[target], product);
  }
}

struct CameraUpdate {
  double residual_sum = 0.0;   // sum |p - h D / V| over the camera's non-empty pixels
  double intensity_sum = 0.0;  // sum p
  double update_sum = 0.0;     // sum |1 - h_new / h_old|
  std::size_t updated = 0;
};

class MentReconstructor final : public Reconstructor {
 public:
  explicit MentReconstructor(const ReconstructionOptions& options) : options_(options) {}
  std::string name() const override { return "ment"; }

 protected:
  SparseVolume run(const ReconstructionInput& input, ReconstructionReport& report) override {
    in_ = prepare_input(input, options_);
    report.threads = in_.threads;
    const std::size_t cams = in_.camera_count();

    const double budget = check_memory(report);
    const GridProjector projector(in_);
    make_planes();
    samples_ = build_ment_samples(in_, projector, measured_, codec_, options_.mlos_threshold, budget);
    // The normalised images are now in measured_; the float copies are not needed any more.
    for (CameraImage& im : in_.images) im.pixels = {};
    report.setup_seconds = elapsed_seconds();

    for (int it = 1; it <= options_.max_iterations; ++it) {
      const auto t0 = std::chrono::steady_clock::now();
      CameraUpdate total;
      for (std::size_t c = 0; c < cams; ++c) {
        const CameraUpdate u = update_camera(c);
        total.residual_sum += u.residual_sum;
        total.intensity_sum += u.intensity_sum;
        total.update_sum += u.update_sum;
        total.updated += u.updated;
      }
      const double residual = total.intensity_sum > 0 ? total.residual_sum / total.intensity_sum : 0.0;
      const double mean_update = total.updated > 0 ? total.update_sum / static_cast<double>(total.updated) : 0.0;
      if (record_iteration(report, it, residual, mean_update, seconds_since(t0), options_.stop_mean_update)) break;
    }

    SparseVolume volume = recover_volume(report);
    report.active_voxels = volume.size();
    in_ = {};
    samples_ = {};
    pseudo_.clear();
    measured_.clear();
    accumulators_.clear();
    return volume;
  }

 private:
  // Up front: the planes (measured, pseudo, one accumulator per thread), the sample list and
  // the output, against the limit. Returns the bytes left for the sample list, which its
  // builder checks as it grows, so that the process never runs out of memory.
  //
  // A sample is non-empty in every camera. Its count is estimated as the product of the
  // cameras' non-empty fractions (bilinear neighbourhoods) times the lattice points, doubled
  // for the correlation of ghosts with particles (the tpiv-thesis support is 1.1-1.3 x the
  // product); it can never exceed the most selective camera's fraction.
  double check_memory(ReconstructionReport& report) {
    const std::size_t cams = in_.camera_count();
    const double fixed = image_bytes(in_, 3 + in_.threads, 1);
    double least = 1.0, product = 1.0;
    for (const CameraImage& im : in_.images) {
      const float cut = cut_of(im);
      auto lit = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < im.width && y < im.height && im.at(x, y) >= cut && im.at(x, y) > 0;
      };
      std::size_t reachable = 0;
      for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) reachable += lit(x, y) || lit(x - 1, y) || lit(x, y - 1) || lit(x - 1, y - 1);
      const double fraction = static_cast<double>(reachable) / static_cast<double>(im.pixels.size());
      least = std::min(least, fraction);
      product *= fraction;
    }
    const double fraction = std::min(least, 2.0 * product);
    const double voxels = fraction * static_cast<double>(in_.grid.voxel_count());
    // Per voxel: kSubsteps samples, the centre's grid index, and 8 B of output.
    const double per_voxel = kSubsteps * ment_bytes_per_sample(cams) + kMentBytesPerCentre + 8.0;
    output_budget_fixed_ = fixed;
    report.estimated_memory_mb = (fixed + per_voxel * voxels) / (1024.0 * 1024.0);
    require_memory(fixed + per_voxel * voxels, options_.memory_limit_mb,
                   fmt::format("MENT on a grid of {} x {} x {} voxels (about {:.2f} % of them in the support)",
                               in_.grid.nx, in_.grid.ny, in_.grid.nz, 100.0 * fraction));
    const double limit_mb = options_.memory_limit_mb > 0 ? options_.memory_limit_mb : usable_memory_mb();
    // The sample list may use what the planes leave, minus room for the output (8 B per
    // voxel-centre sample, i.e. at most 8 / (kSubsteps * bytes per sample + 4) of the list).
    const double list_share = (per_voxel - 8.0) / per_voxel;
    return limit_mb > 0 ? (limit_mb * 1024.0 * 1024.0 - fixed) * list_share : 1e300;
  }

  float cut_of(const CameraImage& im) const { return static_cast<float>(options_.mlos_threshold) * im.max; }

  // p_j thresholded as MLOS does, and h_j^0 of Eq. 3.1: 1 where p_j > 0, else 0.
  void make_planes() {
    measured_.clear();
    pseudo_.clear();
    std::vector<double> lit_pixels;
    std::size_t largest = 0;
    for (const CameraImage& im : in_.images) {
      MentPlane p(im.width, im.height), h(im.width, im.height);
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
      lit_pixels.push_back(lit / (static_cast<double>(im.width) * im.height));
      largest = std::max(largest, p.data.size());
      measured_.push_back(std::move(p));
      pseudo_.push_back(std::move(h));
    }
    codec_ = CellCode(largest);
    order_.resize(in_.camera_count());
    std::iota(order_.begin(), order_.end(), 0);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](std::size_t a, std::size_t b) { return lit_pixels[a] < lit_pixels[b]; });
    accumulators_.assign(static_cast<std::size_t>(in_.threads), std::vector<float>(largest, 0.0f));
  }

  // One MENT step for camera `target` (Eq. 3.2): the denominator from the other cameras'
  // current pseudo-images, then h_target = p_target / denominator.
  CameraUpdate update_camera(std::size_t target) {
    const std::size_t cams = in_.camera_count();
    const MentPlane& mask = measured_[target];
    const std::size_t plane_size = mask.data.size(), stride = static_cast<std::size_t>(mask.stride);
    // The other cameras' planes, most selective first (built per update, outside the hot loop).
    std::vector<PlaneRef> others;
    for (std::size_t c : order_)
      if (c != target) others.push_back({pseudo_[c].data.data(), static_cast<std::size_t>(pseudo_[c].stride), c});

#pragma omp parallel num_threads(in_.threads)
    {
      float* acc = accumulators_[static_cast<std::size_t>(omp_get_thread_num())].data();
      std::fill(acc, acc + plane_size, 0.0f);
#pragma omp for schedule(dynamic, 1)
      for (std::size_t k = 0; k < samples_.slabs.size(); ++k) {
        const MentSlab& slab = samples_.slabs[k];
        const std::size_t n = slab.code.size() / cams;
        if (others.size() == 3)  // four cameras, the usual rig: a fixed-size inner loop
          splat_products<3>(codec_, slab.code.data(), n, cams, others.data(), 3, target, acc, stride);
        else
          splat_products<0>(codec_, slab.code.data(), n, cams, others.data(), others.size(), target, acc, stride);
      }
    }

    MentPlane& h = pseudo_[target];
    CameraUpdate out;
    const int threads = in_.threads;
    double residual_sum = 0, intensity_sum = 0, update_sum = 0;
    std::size_t updated = 0;
#pragma omp parallel for num_threads(threads) schedule(static) \
    reduction(+ : residual_sum, intensity_sum, update_sum, updated)
    for (int y = 0; y < mask.height; ++y)
      for (int x = 0; x < mask.width; ++x) {
        const float p = mask.at(x, y);
        if (!(p > 0.0f)) continue;
        const std::size_t at = static_cast<std::size_t>(y + 1) * stride + x + 1;
        double denominator = 0;
        for (int t = 0; t < threads; ++t) denominator += accumulators_[static_cast<std::size_t>(t)][at];
        denominator /= kSubsteps;
        const double old = h.data[at];
        residual_sum += std::fabs(p - old * denominator);
        intensity_sum += p;
        const double next = denominator > 0 ? p / denominator : 0.0;
        if (old > 0) {
          update_sum += std::fabs(1.0 - next / old);
          ++updated;
        }
        h.data[at] = static_cast<float>(next);
      }
    out.residual_sum = residual_sum;
    out.intensity_sum = intensity_sum;
    out.update_sum = update_sum;
    out.updated = updated;
    return out;
  }

  // Eq. 3.4: E = product of the pseudo-images at the voxel's image positions, block of slices by
  // block in z order, appended straight to the sparse output. Only voxel-centre samples can be non-zero.
  SparseVolume recover_volume(ReconstructionReport& report) {
    const VoxelGrid& g = in_.grid;
    const std::size_t cams = in_.camera_count();
    SparseVolume volume;
    volume.grid = g;
    const double limit_mb = options_.memory_limit_mb > 0 ? options_.memory_limit_mb : usable_memory_mb();
    const double list_bytes = ment_bytes_per_sample(cams) * static_cast<double>(samples_.samples) +
                              kMentBytesPerCentre * static_cast<double>(samples_.centres);
    const double fixed = output_budget_fixed_ + list_bytes;
    const double budget = limit_mb > 0 ? (limit_mb * 1024.0 * 1024.0 - fixed) / 8.0 : 1e300;
    // The output can hold at most one entry per voxel-centre sample: reserve it once when that
    // fits, so the appends never reallocate (no transient double copy).
    if (static_cast<double>(samples_.centres) <= budget) {
      volume.index.reserve(samples_.centres);
      volume.intensity.reserve(samples_.centres);
    }
    bool over_budget = false;
    const CellCode codec = codec_;
    std::vector<PlaneRef> planes;
    for (std::size_t c : order_) planes.push_back({pseudo_[c].data.data(), static_cast<std::size_t>(pseudo_[c].stride), c});

    // Slabs hold blocks of slices in (j, k, i) order; the output wants ascending indices, i.e.
    // (k, j, i): each slab's voxels are bucketed by slice (a stable counting sort).
    const std::uint32_t plane = static_cast<std::uint32_t>(g.nx) * static_cast<std::uint32_t>(g.ny);
    const int slabs = static_cast<int>(samples_.slabs.size());
#pragma omp parallel num_threads(in_.threads)
    {
      std::vector<std::uint32_t> index, sorted_index;
      std::vector<float> value, sorted_value;
      std::vector<std::size_t> start;
#pragma omp for ordered schedule(static, 1)
      for (int b = 0; b < slabs; ++b) {
        const MentSlab& slab = samples_.slabs[static_cast<std::size_t>(b)];
        index.clear();
        value.clear();
        const std::uint32_t* code = slab.code.data();
        for (std::uint32_t n = 0; n < slab.centres; ++n, code += cams) {
          float product = 1.0f;
          for (const PlaneRef& p : planes) product *= codec.read(p.data, p.stride, code[p.camera]);
          if (product > 0.0f && std::isfinite(product)) {
            index.push_back(slab.voxel[n]);
            value.push_back(product);
          }
        }
        const std::uint32_t k0 = static_cast<std::uint32_t>(b * kSlabSlices);
        start.assign(kSlabSlices + 1, 0);
        for (std::uint32_t at : index) ++start[at / plane - k0 + 1];
        for (int q = 0; q < kSlabSlices; ++q) start[q + 1] += start[q];
        sorted_index.resize(index.size());
        sorted_value.resize(value.size());
        for (std::size_t n = 0; n < index.size(); ++n) {
          const std::size_t to = start[index[n] / plane - k0]++;
          sorted_index[to] = index[n];
          sorted_value[to] = value[n];
        }
#pragma omp ordered
        {
          if (!over_budget && static_cast<double>(volume.size() + sorted_index.size()) <= budget) {
            volume.index.insert(volume.index.end(), sorted_index.begin(), sorted_index.end());
            volume.intensity.insert(volume.intensity.end(), sorted_value.begin(), sorted_value.end());
          } else {
            over_budget = true;
          }
        }
      }
    }
    if (over_budget) {
      const std::string what = fmt::format("the MENT volume (more than {} non-zero voxels)", volume.size());
      require_memory(fixed + 8.0 * static_cast<double>(volume.size()) * 2.0, limit_mb, what);
      throw bad_input(fmt::format("reconstruction: {} needs more than the {:.0f} MB available", what, limit_mb));
    }
    report.estimated_memory_mb = (fixed + 8.0 * static_cast<double>(volume.size())) / (1024.0 * 1024.0);
    return volume;
  }

  ReconstructionOptions options_;
  PreparedInput in_;
  std::vector<MentPlane> measured_, pseudo_;
  std::vector<std::vector<float>> accumulators_;  // one per thread, as large as the largest plane
  std::vector<std::size_t> order_;
  CellCode codec_;
  MentSamples samples_;
  double output_budget_fixed_ = 0.0;
};

}  // namespace

std::unique_ptr<Reconstructor> make_ment(const ReconstructionOptions& options) {
  return std::make_unique<MentReconstructor>(options);
}

}  // namespace tomorig::recon::detail
