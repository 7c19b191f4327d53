#include "grid_projector.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::recon::detail {
namespace {

constexpr int kCoarsestStep = 16;
// Where a projection is undefined (behind the camera): far outside every image.
constexpr float kNowhere = -1.0e6f;

int cells_along(int n, int step) { return std::max(1, (n - 1 + step - 1) / step); }

Vec2d project_or_nowhere(const calibration::CameraModel& model, const Vec3d& world) {
  const Vec2d p = model.project(world);
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return {kNowhere, kNowhere};
  return p;
}

// Samples voxel indices 0, s, 2s, ... and always the last one, so the corners are included.
std::vector<int> sample_indices(int n) {
  const int s = std::max(1, n / 32);
  std::vector<int> out;
  for (int i = 0; i < n; i += s) out.push_back(i);
  if (out.back() != n - 1) out.push_back(n - 1);
  return out;
}

}  // namespace

GridProjector::GridProjector(const PreparedInput& in, double tolerance_px) : grid_(in.grid) {
  for (std::size_t c = 0; c < in.camera_count(); ++c) {
    const calibration::CameraModel& model = *in.cameras[c];
    const CameraImage& image = in.images[c];

    // A grid that this camera does not see leaves nothing to reconstruct: refuse it.
    bool seen = false;
    const std::vector<int> is = sample_indices(grid_.nx), js = sample_indices(grid_.ny), ks = sample_indices(grid_.nz);
    for (int k : ks)
      for (int j : js)
        for (int i : is) {
          const Vec2d p = project_or_nowhere(model, grid_.centre_of(i, j, k));
          seen = seen || (p.x >= -0.5 && p.x <= image.width - 0.5 && p.y >= -0.5 && p.y <= image.height - 0.5);
        }
    if (!seen)
      throw bad_input(fmt::format("reconstruction: camera {} sees none of the grid ({} x {} x {} voxels of {} mm "
                                  "from origin ({}, {}, {}) mm): check the grid position and the calibration",
                                  c, grid_.nx, grid_.ny, grid_.nz, grid_.voxel_size, grid_.origin.x, grid_.origin.y,
                                  grid_.origin.z));

    Lattice lattice;
    for (int step = kCoarsestStep; step >= 2; step /= 2) {
      lattice = build(model, step, in.threads);
      lattice.max_error = measure_error(lattice, in.threads);
      if (lattice.max_error <= tolerance_px) break;
    }
    if (lattice.max_error > tolerance_px) {  // exact projection of every voxel
      lattice = {};
      lattice.step = 1;
    }
    lattice.model = &model;
    cams_.push_back(std::move(lattice));
  }
}

GridProjector::Lattice GridProjector::build(const calibration::CameraModel& model, int step, int threads) const {
  Lattice l;
  l.model = &model;
  l.step = step;
  l.nodes_x = cells_along(grid_.nx, step) + 1;
  l.nodes_y = cells_along(grid_.ny, step) + 1;
  l.nodes_z = cells_along(grid_.nz, step) + 1;
  const std::size_t count = static_cast<std::size_t>(l.nodes_x) * l.nodes_y * l.nodes_z;
  l.u.resize(count);
  l.v.resize(count);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int c = 0; c < l.nodes_z; ++c)
    for (int b = 0; b < l.nodes_y; ++b)
      for (int a = 0; a < l.nodes_x; ++a) {
        const Vec2d p = project_or_nowhere(model, grid_.centre_of(a * step, b * step, c * step));
        const std::size_t n = static_cast<std::size_t>(a) + l.nodes_x * (static_cast<std::size_t>(b) + l.nodes_y * c);
        l.u[n] = static_cast<float>(p.x);
        l.v[n] = static_cast<float>(p.y);
      }
  return l;
}

double GridProjector::measure_error(const Lattice& l, int threads) const {
  double worst = 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) reduction(max : worst)
  for (int c = 0; c < l.nodes_z - 1; ++c)
    for (int b = 0; b < l.nodes_y - 1; ++b)
      for (int a = 0; a < l.nodes_x - 1; ++a) {
        auto node = [&](int da, int db, int dc) {
          return static_cast<std::size_t>(a + da) + l.nodes_x * (static_cast<std::size_t>(b + db) + l.nodes_y * (c + dc));
        };
        double u = 0, v = 0;
        bool defined = true;
        for (int d = 0; d < 8; ++d) {
          const std::size_t n = node(d & 1, (d >> 1) & 1, d >> 2);
          defined = defined && l.u[n] != kNowhere;
          u += 0.125 * l.u[n];
          v += 0.125 * l.v[n];
        }
        if (!defined) continue;  // behind the camera: never sampled inside an image
        const double h = 0.5 * l.step;
        const Vec2d p = l.model->project(grid_.centre_of(a * l.step + h, b * l.step + h, c * l.step + h));
        const double err = std::hypot(p.x - u, p.y - v);
        if (std::isfinite(p.x) && std::isfinite(p.y)) worst = std::max(worst, err);
      }
  return worst;
}

namespace {

// Row segments of up to this many lattice nodes live on the stack; longer rows (over 16 000
// voxels at the coarsest step) take a heap buffer.
constexpr int kStackNodes = 1024;

// Scratch for one row's segments: u0, du, v0, dv of `nodes` entries each.
class SegmentBuffer {
 public:
  explicit SegmentBuffer(int nodes) {
    if (nodes > kStackNodes) heap_.resize(static_cast<std::size_t>(nodes) * 4);
    float* base = heap_.empty() ? stack_ : heap_.data();
    u0 = base;
    du = base + nodes;
    v0 = base + 2 * nodes;
    dv = base + 3 * nodes;
  }
  float *u0, *du, *v0, *dv;

 private:
  float stack_[4 * kStackNodes];
  std::vector<float> heap_;
};

}  // namespace

void GridProjector::row(std::size_t c, int j, int k, float* u, float* v) const {
  const Lattice& l = cams_[c];
  if (l.step == 1) {
    for (int i = 0; i < grid_.nx; ++i) {
      const Vec2d p = project_or_nowhere(*l.model, grid_.centre_of(i, j, k));
      u[i] = static_cast<float>(p.x);
      v[i] = static_cast<float>(p.y);
    }
    return;
  }
  SegmentBuffer seg(l.nodes_x);
  const int segments = row_segments(c, j, k, seg.u0, seg.du, seg.v0, seg.dv);
  for (int a = 0; a < segments; ++a) {
    const int i0 = a * l.step, i1 = a == segments - 1 ? grid_.nx : std::min(i0 + l.step, grid_.nx);
    for (int i = i0; i < i1; ++i) {
      const float off = static_cast<float>(i - i0);
      u[i] = seg.u0[a] + seg.du[a] * off;
      v[i] = seg.v0[a] + seg.dv[a] * off;
    }
  }
}

void GridProjector::row_at(std::size_t c, int j, int k, const int* voxels, int count, float* u, float* v) const {
  const Lattice& l = cams_[c];
  if (l.step == 1) {
    for (int n = 0; n < count; ++n) {
      const int i = voxels[n];
      const Vec2d p = project_or_nowhere(*l.model, grid_.centre_of(i, j, k));
      u[i] = static_cast<float>(p.x);
      v[i] = static_cast<float>(p.y);
    }
    return;
  }
  if (count == 0) return;
  // The row's segments (a few dozen), then each listed voxel from its own, as row() does.
  SegmentBuffer seg(l.nodes_x);
  const int segments = row_segments(c, j, k, seg.u0, seg.du, seg.v0, seg.dv);
  for (int n = 0; n < count; ++n) {
    const int i = voxels[n];
    const int a = std::min(i / l.step, segments - 1);
    const float off = static_cast<float>(i - a * l.step);
    u[i] = seg.u0[a] + seg.du[a] * off;
    v[i] = seg.v0[a] + seg.dv[a] * off;
  }
}

GridProjector::Slopes GridProjector::slopes(std::size_t c) const {
  const Lattice& l = cams_[c];
  Slopes out;
  if (l.step == 1) return out;
  for (float u : l.u)
    if (u == kNowhere) return out;
  // The positions are trilinear within a lattice cell, so their partial derivatives there are
  // bounded by the node differences along the cell's edges.
  const int strides[3] = {1, l.nodes_x, l.nodes_x * l.nodes_y};
  const int nodes[3] = {l.nodes_x, l.nodes_y, l.nodes_z};
  const float inverse = 1.0f / static_cast<float>(l.step);
  for (int c2 = 0; c2 < l.nodes_z; ++c2)
    for (int b = 0; b < l.nodes_y; ++b)
      for (int a = 0; a < l.nodes_x; ++a) {
        const int at[3] = {a, b, c2};
        const std::size_t n = static_cast<std::size_t>(a) + l.nodes_x * (static_cast<std::size_t>(b) + l.nodes_y * c2);
        for (int axis = 0; axis < 3; ++axis) {
          if (at[axis] + 1 >= nodes[axis]) continue;
          const std::size_t m = n + static_cast<std::size_t>(strides[axis]);
          out.u[axis] = std::max(out.u[axis], std::fabs(l.u[m] - l.u[n]) * inverse);
          out.v[axis] = std::max(out.v[axis], std::fabs(l.v[m] - l.v[n]) * inverse);
        }
      }
  out.defined = true;
  return out;
}

int GridProjector::max_segments() const {
  int most = 1;
  for (const Lattice& l : cams_) most = std::max(most, l.nodes_x);  // one spare: the last node
  return most;
}

int GridProjector::row_segments(std::size_t c, int j, int k, float* u0, float* du, float* v0, float* dv) const {
  return row_segments(c, j, k, 0.0f, 0.0f, u0, du, v0, dv);
}

int GridProjector::row_segments(std::size_t c, int j, int k, float dj, float dk, float* u0, float* du, float* v0,
                                float* dv) const {
  const Lattice& l = cams_[c];
  if (l.step == 1) return 0;
  const int s = l.step;
  const int cb = std::min(j / s, l.nodes_y - 2), cc = std::min(k / s, l.nodes_z - 2);
  const float fb = (static_cast<float>(j - cb * s) + dj) / s, fc = (static_cast<float>(k - cc * s) + dk) / s;
  const float w00 = (1 - fb) * (1 - fc), w10 = fb * (1 - fc), w01 = (1 - fb) * fc, w11 = fb * fc;
  const std::size_t plane = static_cast<std::size_t>(l.nodes_x) * l.nodes_y;
  const std::size_t r00 = static_cast<std::size_t>(l.nodes_x) * cb + plane * cc;
  const std::size_t r10 = r00 + l.nodes_x, r01 = r00 + plane, r11 = r00 + plane + l.nodes_x;
  const float* pu = l.u.data();
  const float* pv = l.v.data();
  // The nodes as row() computes them (a loop without a carried value, so it vectorises) ...
  for (int a = 0; a < l.nodes_x; ++a) {
    u0[a] = w00 * pu[r00 + a] + w10 * pu[r10 + a] + w01 * pu[r01 + a] + w11 * pu[r11 + a];
    v0[a] = w00 * pv[r00 + a] + w10 * pv[r10 + a] + w01 * pv[r01 + a] + w11 * pv[r11 + a];
  }
  // ... and the slopes. The step is a power of two, so multiplying by its inverse is exact:
  // the same bits as row()'s division.
  const float inverse = 1.0f / static_cast<float>(s);
  for (int a = 0; a + 1 < l.nodes_x; ++a) {
    du[a] = (u0[a + 1] - u0[a]) * inverse;
    dv[a] = (v0[a + 1] - v0[a]) * inverse;
  }
  return l.nodes_x - 1;
}

}  // namespace tomorig::recon::detail
