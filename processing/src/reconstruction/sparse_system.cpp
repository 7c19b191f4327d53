#include "sparse_system.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <omp.h>

#include "fast_math.h"

namespace tomorig::recon::detail {
namespace {

// Bounds on ln(I / I~). A pixel recorded as 0 under a projected voxel would set R = 0 and kill
// the voxel outright however small its weight there; the floor keeps it a strong but graded
// penalty. The ceiling stops a voxel whose projection has decayed to ~0 from exploding.
constexpr float kMinLogRatio = -13.8f;  // R >= 1e-6
constexpr float kMaxLogRatio = 6.9f;   // R <= 1e3
// The ratio itself is clamped a little wider first, so that fast_log only sees normal floats.
constexpr float kMinRatio = 1e-7f, kMaxRatio = 1e4f;
// Projected intensities below this carry no information (no live voxel reaches the pixel).
constexpr float kNoProjection = 1e-12f;

// Where a voxel's p x p weights come from. P = 0 selects the patch size at run time; 3, 4 and
// 5 are unrolled by the compiler.
//   Separable: an axis-aligned PSF, weight(a, b) = wu[a] * wv[b] from two LUT rows;
//   Block:     a rotated PSF, a full p x p block from the 2-D LUT.
template <int P>
struct Separable {
  const std::uint16_t* row_u;
  const std::uint16_t* row_v;
  const float* lut_u;
  const float* lut_v;
  int runtime_patch;

  int p() const { return P ? P : runtime_patch; }
  void scatter(std::size_t n, float en, float* base, int stride) const {
    const int q = p();
    const float* wu = lut_u + static_cast<std::size_t>(row_u[n]) * q;
    const float* wv = lut_v + static_cast<std::size_t>(row_v[n]) * q;
    for (int b = 0; b < q; ++b) {
      const float ev = en * wv[b];
      float* row = base + static_cast<std::ptrdiff_t>(b) * stride;
      for (int a = 0; a < q; ++a) row[a] += ev * wu[a];
    }
  }
  float gather(std::size_t n, const float* base, int stride) const {
    const int q = p();
    const float* wu = lut_u + static_cast<std::size_t>(row_u[n]) * q;
    const float* wv = lut_v + static_cast<std::size_t>(row_v[n]) * q;
    float s = 0.0f;
    for (int b = 0; b < q; ++b) {
      const float* row = base + static_cast<std::ptrdiff_t>(b) * stride;
      float r = 0.0f;
      for (int a = 0; a < q; ++a) r += wu[a] * row[a];
      s += wv[b] * r;
    }
    return s;
  }
};

template <int P>
struct Block {
  const std::uint32_t* row;
  const float* lut;
  int runtime_patch;

  int p() const { return P ? P : runtime_patch; }
  void scatter(std::size_t n, float en, float* base, int stride) const {
    const int q = p();
    const float* w = lut + static_cast<std::size_t>(row[n]) * q * q;
    for (int b = 0; b < q; ++b) {
      float* r = base + static_cast<std::ptrdiff_t>(b) * stride;
      for (int a = 0; a < q; ++a) r[a] += en * w[b * q + a];
    }
  }
  float gather(std::size_t n, const float* base, int stride) const {
    const int q = p();
    const float* w = lut + static_cast<std::size_t>(row[n]) * q * q;
    float s = 0.0f;
    for (int b = 0; b < q; ++b) {
      const float* r = base + static_cast<std::ptrdiff_t>(b) * stride;
      for (int a = 0; a < q; ++a) s += w[b * q + a] * r[a];
    }
    return s;
  }
};

template <class W>
void scatter(const W& w, const std::int32_t* offset, const float* e, std::size_t begin, std::size_t end, float* image,
             int stride) {
  for (std::size_t n = begin; n < end; ++n) {
    const float en = e[n];
    if (en == 0.0f) continue;
    w.scatter(n, en, image + offset[n], stride);
  }
}

template <class W>
double update_kernel(const W& w, const std::int32_t* offset, const float* log_ratio, int stride, std::size_t voxels,
                     float* e, float mu, int threads) {
  double sum = 0.0;
  const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(voxels);
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : sum)
  for (std::ptrdiff_t n = 0; n < count; ++n) {
    if (e[n] == 0.0f) continue;
    const float factor = fast_exp(mu * w.gather(static_cast<std::size_t>(n), log_ratio + offset[n], stride));
    e[n] *= factor;
    sum += std::fabs(1.0f - factor);
  }
  return sum;
}

template <class W>
void accumulate_kernel(const W& w, const std::int32_t* offset, const float* log_ratio, int stride, std::size_t voxels,
                       float* acc, int threads) {
  const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(voxels);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t n = 0; n < count; ++n)
    acc[n] += w.gather(static_cast<std::size_t>(n), log_ratio + offset[n], stride);
}

// Calls visit(n, u, v) with the image position in camera c of every voxel index[n]. Voxels of
// one grid row come in runs (the index is ascending), so each run costs one row_at() call.
template <class F>
void for_each_position(const PreparedInput& in, const std::vector<std::uint32_t>& index, const GridProjector& projector,
                       std::size_t c, F&& visit) {
  const VoxelGrid& g = in.grid;
  const std::uint32_t nx = static_cast<std::uint32_t>(g.nx);
  constexpr std::size_t kBlock = 1 << 16;
  const std::ptrdiff_t blocks = static_cast<std::ptrdiff_t>((index.size() + kBlock - 1) / kBlock);
#pragma omp parallel num_threads(in.threads)
  {
    std::vector<float> u(static_cast<std::size_t>(g.nx)), v(static_cast<std::size_t>(g.nx));
    std::vector<int> columns(static_cast<std::size_t>(g.nx));
#pragma omp for schedule(static)
    for (std::ptrdiff_t b = 0; b < blocks; ++b) {
      const std::size_t end = std::min(index.size(), static_cast<std::size_t>(b + 1) * kBlock);
      for (std::size_t first = static_cast<std::size_t>(b) * kBlock; first < end;) {
        const std::uint32_t row = index[first] / nx;
        std::size_t last = first;
        int count = 0;
        while (last < end && index[last] / nx == row) columns[count++] = static_cast<int>(index[last++] - row * nx);
        projector.row_at(c, static_cast<int>(row % static_cast<std::uint32_t>(g.ny)),
                         static_cast<int>(row / static_cast<std::uint32_t>(g.ny)), columns.data(), count, u.data(),
                         v.data());
        for (std::size_t n = first; n < last; ++n) {
          const int i = columns[n - first];
          visit(n, u[i], v[i]);
        }
        first = last;
      }
    }
  }
}

}  // namespace

template <class F>
void SparseSystem::with_weights(const Camera& cam, F&& kernel) const {
  // One instantiation per patch size the compiler can unroll, and a run-time one for the rest.
  auto dispatch = [&](auto patch_constant) {
    constexpr int P = decltype(patch_constant)::value;
    if (cam.rotated)
      kernel(Block<P>{cam.row_2d.data(), cam.block_weights.table(), patch_});
    else
      kernel(Separable<P>{cam.row_u.data(), cam.row_v.data(), cam.u_weights.table(), cam.v_weights.table(), patch_});
  };
  switch (patch_) {
    case 3: dispatch(std::integral_constant<int, 3>{}); break;
    case 5: dispatch(std::integral_constant<int, 5>{}); break;
    default: dispatch(std::integral_constant<int, 0>{}); break;
  }
}

SparseSystem::SparseSystem(const PreparedInput& in, const std::vector<std::uint32_t>& index,
                           const GridProjector& projector, int patch, int lut_steps, SparseSystem* recycle)
    : patch_(patch), voxels_(index.size()) {
  const VoxelGrid& g = in.grid;
  const std::size_t plane = static_cast<std::size_t>(g.nx) * g.ny;
  std::vector<Camera> old;
  if (recycle) {
    old = std::move(recycle->cams_);
    scratch_ = std::move(recycle->scratch_);
    *recycle = SparseSystem();
  }
  std::size_t largest_image = 0;
  for (std::size_t c = 0; c < in.camera_count(); ++c) {
    // A recycled camera's arrays are resized below (capacity kept, every entry rewritten); the
    // ones this system does not use are emptied, as compact() and the kernels go by emptiness.
    Camera cam;
    if (c < old.size()) {
      Camera& o = old[c];
      cam.measured = std::move(o.measured);
      cam.projection = std::move(o.projection);
      cam.log_ratio = std::move(o.log_ratio);
      cam.offset = std::move(o.offset);
      cam.row_u = std::move(o.row_u);
      cam.row_v = std::move(o.row_v);
      cam.row_2d = std::move(o.row_2d);
      cam.row_u.clear();
      cam.row_v.clear();
      cam.row_2d.clear();
    }
    const CameraImage& image = in.images[c];
    cam.width = image.width;
    cam.height = image.height;
    cam.pad = patch + 1;
    cam.stride = cam.width + 2 * cam.pad;
    const std::size_t size = static_cast<std::size_t>(cam.stride) * (cam.height + 2 * cam.pad);
    largest_image = std::max(largest_image, size);
    cam.measured.assign(size, 0.0f);
    for (int y = 0; y < cam.height; ++y)
      std::copy_n(image.pixels.data() + static_cast<std::size_t>(y) * cam.width, cam.width,
                  cam.measured.data() + static_cast<std::size_t>(y + cam.pad) * cam.stride + cam.pad);
    cam.projection.assign(size, 0.0f);
    cam.log_ratio.assign(size, 0.0f);

    std::vector<PsfSample> psf_of_slice(static_cast<std::size_t>(g.nz));
    std::vector<double> sigma_u(g.nz), sigma_v(g.nz);
    for (int k = 0; k < g.nz; ++k) {
      const PsfSample s = in.psf[c].at(g.origin.z + k * g.voxel_size);
      psf_of_slice[static_cast<std::size_t>(k)] = s;
      sigma_u[k] = s.sigma_u_px;
      sigma_v[k] = s.sigma_v_px;
      cam.rotated = cam.rotated || is_rotated(s);
    }
    if (cam.rotated) {
      // Placement and phase from one-level axis tables (their row is the phase), weights
      // from the 2-D table.
      cam.u_weights = AxisWeights(std::vector<double>(1, 1.0), patch, lut_steps);
      cam.v_weights = cam.u_weights;
      cam.block_weights = PatchWeights(psf_of_slice, patch, lut_steps, in.threads);
      cam.row_2d.resize(voxels_);
    } else {
      cam.u_weights = AxisWeights(sigma_u, patch, lut_steps);
      cam.v_weights = AxisWeights(sigma_v, patch, lut_steps);
      cam.row_u.resize(voxels_);
      cam.row_v.resize(voxels_);
    }

    cam.offset.resize(voxels_);
    for_each_position(in, index, projector, c, [&](std::size_t n, float u, float v) {
      const int k = static_cast<int>(index[n] / plane);
      int su = 0, sv = 0;
      if (cam.rotated) {
        std::uint16_t qu = 0, qv = 0;
        cam.u_weights.locate(u, 0, su, qu);
        cam.v_weights.locate(v, 0, sv, qv);
        cam.row_2d[n] = cam.block_weights.row(k, qu, qv);
      } else {
        cam.u_weights.locate(u, k, su, cam.row_u[n]);
        cam.v_weights.locate(v, k, sv, cam.row_v[n]);
      }
      // Active voxels image inside every camera, so this clamp never moves one; it only
      // guarantees that no patch can reach outside the padded image.
      su = std::clamp(su, -cam.pad, cam.width + cam.pad - patch);
      sv = std::clamp(sv, -cam.pad, cam.height + cam.pad - patch);
      cam.offset[n] = (sv + cam.pad) * cam.stride + su + cam.pad;
    });
    cams_.push_back(std::move(cam));
  }
  // Each thread clears its scratch image before every projection, so only the size matters.
  scratch_.resize(static_cast<std::size_t>(std::max(0, in.threads - 1)));
  for (std::vector<float>& image : scratch_) image.resize(largest_image);
}

double SparseSystem::estimate_bytes(const PreparedInput& in, std::size_t voxels, int patch, int threads) {
  const double cams = static_cast<double>(in.camera_count());
  // index + intensity + SMART accumulator + MLOS value, and per camera: offset and two LUT
  // rows (or one 2-D row).
  const double per_voxel = 16.0 + cams * 8.0;
  return per_voxel * static_cast<double>(voxels) + image_bytes(in, 3, patch + 1) +
         image_bytes(in, 1, patch + 1) / cams * std::max(0, threads - 1);
}

void SparseSystem::compact(const std::vector<std::uint32_t>& kept, int threads) {
  // In place: kept[n] >= n, so every entry is read before it can be overwritten.
  const int cams = static_cast<int>(cams_.size());
#pragma omp parallel for num_threads(threads) schedule(static, 1)
  for (int c = 0; c < cams; ++c) {
    Camera& cam = cams_[static_cast<std::size_t>(c)];
    auto keep = [&](auto& values) {
      if (values.empty()) return;
      for (std::size_t n = 0; n < kept.size(); ++n) values[n] = values[kept[n]];
      values.resize(kept.size());
    };
    keep(cam.offset);
    keep(cam.row_u);
    keep(cam.row_v);
    keep(cam.row_2d);
  }
  voxels_ = kept.size();
}

bool SparseSystem::inside(std::size_t c, std::int32_t pixel) const {
  const Camera& cam = cams_[c];
  const int y = pixel / cam.stride - cam.pad, x = pixel % cam.stride - cam.pad;
  return x >= 0 && x < cam.width && y >= 0 && y < cam.height;
}

PixelResidual SparseSystem::project(std::size_t c, const float* e, int threads) {
  Camera& cam = cams_[c];
  const std::size_t size = cam.measured.size();
  const int rows = cam.height + 2 * cam.pad;
  const int team = std::max(1, std::min(threads, static_cast<int>(scratch_.size()) + 1));
  double abs_difference = 0.0, measured = 0.0;
#pragma omp parallel num_threads(team)
  {
    // Each thread scatters a contiguous block of voxels into its own image (no atomics);
    // the images are then summed row by row, and the log ratio computed in the same pass.
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    float* image = t == 0 ? cam.projection.data() : scratch_[t - 1].data();
    std::fill(image, image + size, 0.0f);
    const std::size_t begin = voxels_ * t / nt, end = voxels_ * (t + 1) / nt;
    with_weights(cam, [&](const auto& w) {
      scatter(w, cam.offset.data(), e, begin, end, image, cam.stride);
    });
#pragma omp barrier
#pragma omp for schedule(static) reduction(+ : abs_difference, measured)
    for (int y = 0; y < rows; ++y) {
      float* proj = cam.projection.data() + static_cast<std::size_t>(y) * cam.stride;
      for (int s = 1; s < nt; ++s) {
        const float* other = scratch_[s - 1].data() + static_cast<std::size_t>(y) * cam.stride;
#pragma omp simd
        for (int x = 0; x < cam.stride; ++x) proj[x] += other[x];
      }
      const int iy = y - cam.pad;
      if (iy < 0 || iy >= cam.height) continue;  // padding: log ratio stays 0
      const float* meas = cam.measured.data() + static_cast<std::size_t>(y) * cam.stride + cam.pad;
      float* lr = cam.log_ratio.data() + static_cast<std::size_t>(y) * cam.stride + cam.pad;
      const float* pr = proj + cam.pad;
      float row_diff = 0.0f, row_meas = 0.0f;
      for (int x = 0; x < cam.width; ++x) {
        const float i_meas = meas[x], i_proj = pr[x];
        row_diff += std::fabs(i_meas - i_proj);
        row_meas += i_meas;
        float l = 0.0f;
        if (i_proj > kNoProjection)
          l = i_meas > 0.0f ? std::clamp(fast_log(std::clamp(i_meas / i_proj, kMinRatio, kMaxRatio)), kMinLogRatio, kMaxLogRatio)
                             : kMinLogRatio;
        lr[x] = l;
      }
      abs_difference += row_diff;
      measured += row_meas;
    }
  }
  return {abs_difference, measured};
}

double SparseSystem::update(std::size_t c, float* e, float mu, int threads) const {
  const Camera& cam = cams_[c];
  double sum = 0.0;
  with_weights(cam, [&](const auto& w) {
    sum = update_kernel(w, cam.offset.data(), cam.log_ratio.data(), cam.stride, voxels_, e, mu, threads);
  });
  return sum;
}

void SparseSystem::accumulate(std::size_t c, float* acc, int threads) const {
  const Camera& cam = cams_[c];
  with_weights(cam, [&](const auto& w) {
    accumulate_kernel(w, cam.offset.data(), cam.log_ratio.data(), cam.stride, voxels_, acc, threads);
  });
}

}  // namespace tomorig::recon::detail
