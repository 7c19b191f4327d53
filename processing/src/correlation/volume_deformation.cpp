#include "correlation/volume_deformation.h"

#include "correlation/flush_denormals.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tomorig::piv::detail {
namespace {

int thread_count(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

// floor() as an int without the libm call (x86-64 without SSE4.1 has no rounding instruction);
// the same value as std::floor for the coordinates used here (|x| far below 2^31).
inline int floor_int(float x) {
  const int t = static_cast<int>(x);
  return t - (x < static_cast<float>(t));
}

// The recursive cubic B-spline prefilter (pole sqrt(3) - 2, mirror boundaries) on `width`
// lines of n elements at once: element k of every line is the contiguous row
// base[k * stride .. k * stride + width).
void prefilter_rows(float* base, std::size_t stride, int n, int width) {
  if (n < 2) return;
  constexpr float pole = -0.2679491924311228f;
  constexpr float gain = 6.0f;
  auto row = [&](int k) { return base + static_cast<std::size_t>(k) * stride; };
  for (int k = 0; k < n; ++k) {
    float* r = row(k);
#pragma omp simd
    for (int x = 0; x < width; ++x) r[x] *= gain;
  }
  const int horizon = std::min(n, 30);
  float zk = pole;
  for (int k = 1; k < horizon; ++k, zk *= pole) {
    float* r0 = row(0);
    const float* r = row(k);
#pragma omp simd
    for (int x = 0; x < width; ++x) r0[x] += zk * r[x];
  }
  for (int k = 1; k < n; ++k) {
    float* r = row(k);
    const float* p = row(k - 1);
#pragma omp simd
    for (int x = 0; x < width; ++x) r[x] += pole * p[x];
  }
  {
    float* r = row(n - 1);
    const float* p = row(n - 2);
    constexpr float end_gain = pole / (pole * pole - 1.0f);
#pragma omp simd
    for (int x = 0; x < width; ++x) r[x] = end_gain * (r[x] + pole * p[x]);
  }
  for (int k = n - 2; k >= 0; --k) {
    float* r = row(k);
    const float* next = row(k + 1);
#pragma omp simd
    for (int x = 0; x < width; ++x) r[x] = pole * (next[x] - r[x]);
  }
}

float sample_trilinear(const VolumeView& v, float x, float y, float z) {
  const int i = floor_int(x), j = floor_int(y), k = floor_int(z);
  const float fx = x - i, fy = y - j, fz = z - k;
  float result = 0.0f;
  for (int dk = 0; dk <= 1; ++dk) {
    const int zz = k + dk;
    if (zz < 0 || zz >= v.nz) continue;
    const float wz = dk ? fz : 1.0f - fz;
    for (int dj = 0; dj <= 1; ++dj) {
      const int yy = j + dj;
      if (yy < 0 || yy >= v.ny) continue;
      const float wy = dj ? fy : 1.0f - fy;
      const float* row = v.data + v.linear(0, yy, zz);
      float line = 0.0f;
      if (i >= 0 && i < v.nx) line += (1.0f - fx) * row[i];
      if (i + 1 >= 0 && i + 1 < v.nx) line += fx * row[i + 1];
      result += wz * wy * line;
    }
  }
  return result;
}

void bspline_weights(float t, float w[4]) {
  const float t2 = t * t, t3 = t2 * t, u = 1.0f - t;
  constexpr float sixth = 1.0f / 6.0f;  // a multiply: a division by 6 costs as much as the taps
  w[0] = u * u * u * sixth;
  w[1] = (4.0f - 6.0f * t2 + 3.0f * t3) * sixth;
  w[2] = (1.0f + 3.0f * t + 3.0f * t2 - 3.0f * t3) * sixth;
  w[3] = t3 * sixth;
}

int mirror(int i, int n) {
  if (n == 1) return 0;
  const int period = 2 * n - 2;
  i = std::abs(i) % period;
  return i < n ? i : period - i;
}

float sample_bspline(const VolumeView& c, float x, float y, float z) {
  if (x < -0.5f || y < -0.5f || z < -0.5f || x > c.nx - 0.5f || y > c.ny - 0.5f || z > c.nz - 0.5f) return 0.0f;
  const int i = floor_int(x), j = floor_int(y), k = floor_int(z);
  float wx[4], wy[4], wz[4];
  bspline_weights(x - i, wx);
  bspline_weights(y - j, wy);
  bspline_weights(z - k, wz);
  float result = 0.0f;
  if (i >= 1 && j >= 1 && k >= 1 && i + 2 < c.nx && j + 2 < c.ny && k + 2 < c.nz) {
    // Interior: the 4 x 4 x 4 support needs no mirroring (almost every voxel).
    const float* base = c.data + c.linear(i - 1, j - 1, k - 1);
    const std::size_t sy = static_cast<std::size_t>(c.nx), sz = sy * static_cast<std::size_t>(c.ny);
    for (int dk = 0; dk < 4; ++dk) {
      float plane = 0.0f;
      for (int dj = 0; dj < 4; ++dj) {
        const float* row = base + dk * sz + dj * sy;
        plane += wy[dj] * (wx[0] * row[0] + wx[1] * row[1] + wx[2] * row[2] + wx[3] * row[3]);
      }
      result += wz[dk] * plane;
    }
    return result;
  }
  int ix[4];
  for (int a = 0; a < 4; ++a) ix[a] = mirror(i - 1 + a, c.nx);
  for (int dk = 0; dk < 4; ++dk) {
    const int zz = mirror(k - 1 + dk, c.nz);
    for (int dj = 0; dj < 4; ++dj) {
      const float* row = c.data + c.linear(0, mirror(j - 1 + dj, c.ny), zz);
      const float line = wx[0] * row[ix[0]] + wx[1] * row[ix[1]] + wx[2] * row[ix[2]] + wx[3] * row[ix[3]];
      result += wz[dk] * wy[dj] * line;
    }
  }
  return result;
}

}  // namespace

void locate_axis(double p, double origin, double spacing, int n, int& i0, double& frac) {
  double u = spacing > 0 ? (p - origin) / spacing : 0.0;
  // Beyond the outermost nodes: linear extrapolation of the end cell, for at most one node
  // spacing (the outermost half window). A constant there (the old rule) deforms the
  // boundary windows with the wrong gradient and biased the next-to-boundary nodes.
  u = std::clamp(u, -1.0, static_cast<double>(n));
  i0 = std::clamp(static_cast<int>(std::floor(u)), 0, std::max(n - 2, 0));
  frac = n > 1 ? u - i0 : 0.0;
}

void downsample_sum(const VolumeView& v, int factor, int threads, std::vector<float>& out) {
  const int nx = v.nx / factor, ny = v.ny / factor, nz = v.nz / factor;
  out.assign(static_cast<std::size_t>(nx) * ny * nz, 0.0f);
#pragma omp parallel for num_threads(thread_count(threads)) schedule(static)
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      float* dst = out.data() + static_cast<std::size_t>(nx) * (j + static_cast<std::size_t>(ny) * k);
      for (int dk = 0; dk < factor; ++dk)
        for (int dj = 0; dj < factor; ++dj) {
          const float* src = v.data + v.linear(0, j * factor + dj, k * factor + dk);
          for (int i = 0; i < nx; ++i)
            for (int di = 0; di < factor; ++di) dst[i] += src[i * factor + di];
        }
    }
}

void bspline_coefficients(const VolumeView& samples, int threads, std::vector<float>& out) {
  const int t = thread_count(threads);
  const int nx = samples.nx, ny = samples.ny, nz = samples.nz;
  out.resize(samples.count());  // every element is written below
  const std::size_t sy = nx, sz = static_cast<std::size_t>(nx) * ny;
#pragma omp parallel num_threads(t)
  {
    const FlushDenormals flush;
    // x and y slice by slice, while the slice is in cache: the samples are read straight into
    // the x lines (no separate copy), and the y recursion runs on the slice just written. Two
    // sweeps over the volume in all (this one and z) instead of four (copy, x, y, z); measured
    // on the tpiv-thesis FMART pair, both volumes' coefficients took 0.12 s instead of 0.13.
    // x: kLines lines at a time, transposed into a small buffer (element k of every line one
    // contiguous row) so that the recursion runs over the lines in float lanes as in y and z;
    // one line at a time it is a chain of dependent scalar operations.
    constexpr int kLines = 8;
    std::vector<float> lines(static_cast<std::size_t>(nx) * kLines);
#pragma omp for schedule(static)
    for (int k = 0; k < nz; ++k) {
      const float* source = samples.data + k * sz;
      float* slice = out.data() + k * sz;
      for (int j0 = 0; j0 < ny; j0 += kLines) {
        const int width = std::min(kLines, ny - j0);
        for (int l = 0; l < width; ++l)
          for (int i = 0; i < nx; ++i) lines[static_cast<std::size_t>(i) * kLines + l] = source[(j0 + l) * sy + i];
        prefilter_rows(lines.data(), kLines, nx, width);
        for (int l = 0; l < width; ++l)
          for (int i = 0; i < nx; ++i) slice[(j0 + l) * sy + i] = lines[static_cast<std::size_t>(i) * kLines + l];
      }
      // y: all lines of the slice advance together, row by row, so the inner loop runs over
      // contiguous x (vectorised, no strided gathers).
      prefilter_rows(slice, sy, ny, nx);
    }
    // z: likewise over the rows of each x-z sheet.
#pragma omp for schedule(static)
    for (int j = 0; j < ny; ++j) prefilter_rows(out.data() + j * sy, sz, nz, nx);
  }
}

Vec3f sample_field(const VectorField& f, double x, double y, double z) {
  int i, j, k;
  double fx, fy, fz;
  locate_axis(x, f.origin.x, f.spacing.x, f.nx, i, fx);
  locate_axis(y, f.origin.y, f.spacing.y, f.ny, j, fy);
  locate_axis(z, f.origin.z, f.spacing.z, f.nz, k, fz);
  double r[3] = {0, 0, 0};
  for (int dk = 0; dk <= 1; ++dk) {
    const double wz = dk ? fz : 1.0 - fz;
    if (wz == 0.0 || (f.nz == 1 && dk)) continue;
    for (int dj = 0; dj <= 1; ++dj) {
      const double wy = dj ? fy : 1.0 - fy;
      if (wy == 0.0 || (f.ny == 1 && dj)) continue;
      for (int di = 0; di <= 1; ++di) {
        const double w = wz * wy * (di ? fx : 1.0 - fx);
        if (w == 0.0 || (f.nx == 1 && di)) continue;
        const Vec3f& d = f.displacement[f.linear(i + di, j + dj, k + dk)];
        r[0] += w * d.x;
        r[1] += w * d.y;
        r[2] += w * d.z;
      }
    }
  }
  return {static_cast<float>(r[0]), static_cast<float>(r[1]), static_cast<float>(r[2])};
}

void RowPredictor::set_row(double y, double z) {
  int j, k;
  double fy, fz;
  locate_axis(y, f_.origin.y, f_.spacing.y, f_.ny, j, fy);
  locate_axis(z, f_.origin.z, f_.spacing.z, f_.nz, k, fz);
  columns_.assign(3 * static_cast<std::size_t>(f_.nx), 0.0);
  for (int dk = 0; dk <= 1; ++dk) {
    const double wz = dk ? fz : 1.0 - fz;
    if (wz == 0.0 || (f_.nz == 1 && dk)) continue;
    for (int dj = 0; dj <= 1; ++dj) {
      const double wy = dj ? fy : 1.0 - fy;
      if (wy == 0.0 || (f_.ny == 1 && dj)) continue;
      const double w = wz * wy;
      for (int i = 0; i < f_.nx; ++i) {
        const Vec3f& d = f_.displacement[f_.linear(i, j + dj, k + dk)];
        columns_[3 * i] += w * d.x;
        columns_[3 * i + 1] += w * d.y;
        columns_[3 * i + 2] += w * d.z;
      }
    }
  }
}

Vec3f RowPredictor::at(double x) const {
  int i;
  double fx;
  locate_axis(x, f_.origin.x, f_.spacing.x, f_.nx, i, fx);
  double r[3] = {0, 0, 0};
  for (int di = 0; di <= 1; ++di) {
    const double w = di ? fx : 1.0 - fx;
    if (w == 0.0 || (f_.nx == 1 && di)) continue;
    const double* c = columns_.data() + 3 * static_cast<std::size_t>(i + di);
    r[0] += w * c[0];
    r[1] += w * c[1];
    r[2] += w * c[2];
  }
  return {static_cast<float>(r[0]), static_cast<float>(r[1]), static_cast<float>(r[2])};
}

void signal_support(const VolumeView& v, float relative_threshold, float largest, int radius, int threads,
                    std::vector<std::uint8_t>& out, std::vector<std::uint8_t>& scratch) {
  const int t = thread_count(threads);
  const std::size_t count = v.count();
  const float threshold = relative_threshold * largest;
  // Every byte of both is written below before it is read.
  std::vector<std::uint8_t>& mask = scratch;
  std::vector<std::uint8_t>& spread = out;
  mask.resize(count);
  spread.resize(count);
  // Dilation by `radius` as three separable maxima (x, then y, then z) of width 2 radius + 1.
  const std::size_t sy = v.nx, sz = static_cast<std::size_t>(v.nx) * v.ny;
#pragma omp parallel num_threads(t)
  {
#pragma omp for schedule(static)
    for (int k = 0; k < v.nz; ++k)
      for (int j = 0; j < v.ny; ++j) {
        const float* src = v.data + j * sy + k * sz;
        std::uint8_t* dst = spread.data() + j * sy + k * sz;
        int last = -1000000;  // last x above the threshold
        for (int i = 0; i < v.nx + radius; ++i) {
          if (i < v.nx && std::abs(src[i]) > threshold) last = i;
          const int x = i - radius;
          if (x >= 0) dst[x] = (i - last) <= 2 * radius;
        }
      }
    // y: row k*sz + j*sy of mask = OR of spread rows j - r .. j + r.
#pragma omp for schedule(static)
    for (int k = 0; k < v.nz; ++k)
      for (int j = 0; j < v.ny; ++j) {
        std::uint8_t* dst = mask.data() + j * sy + k * sz;
        std::fill(dst, dst + v.nx, std::uint8_t{0});
        for (int jj = std::max(0, j - radius); jj <= std::min(v.ny - 1, j + radius); ++jj) {
          const std::uint8_t* src = spread.data() + jj * sy + k * sz;
#pragma omp simd
          for (int i = 0; i < v.nx; ++i) dst[i] |= src[i];
        }
      }
    // z: into spread, then the result is spread.
#pragma omp for schedule(static)
    for (int k = 0; k < v.nz; ++k) {
      std::uint8_t* dst = spread.data() + k * sz;
      std::fill(dst, dst + sz, std::uint8_t{0});
      for (int kk = std::max(0, k - radius); kk <= std::min(v.nz - 1, k + radius); ++kk) {
        const std::uint8_t* src = mask.data() + kk * sz;
#pragma omp simd
        for (std::size_t m = 0; m < sz; ++m) dst[m] |= src[m];
      }
    }
  }
}

namespace {

// The predictor's x-interpolation is the same on every row: each voxel's cell (left node) and
// fraction, found once per deformation instead of per voxel (locate_axis in double).
struct AxisCells {
  std::vector<int> cell;
  std::vector<float> frac;
};

AxisCells axis_cells(int voxels, int factor, double offset, double origin, double spacing, int nodes) {
  AxisCells c;
  c.cell.resize(voxels);
  c.frac.resize(voxels);
  for (int i = 0; i < voxels; ++i) {
    double frac;
    locate_axis(i * factor + offset, origin, spacing, nodes, c.cell[i], frac);
    c.frac[i] = static_cast<float>(frac);
  }
  return c;
}

// The 4 x 4 x 4 B-spline sum of an interior sample: the 16 rows of 4 coefficients weighted by
// wz * wy into 4 lanes, then the lanes by wx (two packed multiply-adds per row).
inline float bspline_interior(const float* base, std::size_t sy, std::size_t sz, const float wx[4], const float wy[4],
                              const float wz[4]) {
  float acc[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int dk = 0; dk < 4; ++dk)
    for (int dj = 0; dj < 4; ++dj) {
      const float w = wz[dk] * wy[dj];
      const float* row = base + dk * sz + dj * sy;
#pragma omp simd
      for (int l = 0; l < 4; ++l) acc[l] += w * row[l];
    }
  return (wx[0] * acc[0] + wx[1] * acc[1]) + (wx[2] * acc[2] + wx[3] * acc[3]);
}

// Per-thread buffers of deform_row, sized once per thread.
struct RowScratch {
  std::vector<float> x, y, z;  // source positions of the row's voxels
  std::vector<int> nearest;    // linear index of the voxel nearest to each source position
  std::vector<int> kept;       // the voxels whose source has signal
  explicit RowScratch(int n) : x(n), y(n), z(n), nearest(n), kept(n) {}
};

// One deformed row: out[i] = v(i + sign * h(i), j + ..., k + ...), 0 where the support (if any)
// says the source has no signal. The support test runs without branches over the whole row
// and lists the voxels to interpolate (a mask of irregular particle images mispredicts any
// per-voxel branch); only those are evaluated.
// (Compiled also for AVX-512 and AVX2, chosen at run time: fused multiply-adds in the B-spline
// sums and wider lanes in the row loops.)
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] float deform_row(
    const VolumeView& v, const std::uint8_t* support, Interpolation interpolation, int j, int k,
                float sign, const float* hx, const float* hy, const float* hz, int next_dy, int next_dz, RowScratch& s,
                float* out) {
  const std::size_t sy = static_cast<std::size_t>(v.nx), sz = sy * static_cast<std::size_t>(v.ny);
  const int n = v.nx;
  if (n <= 0) return 0.0f;
  float* xs = s.x.data();
  float* ys = s.y.data();
  float* zs = s.z.data();
#pragma omp simd
  for (int i = 0; i < n; ++i) {
    xs[i] = i + sign * hx[i];
    ys[i] = j + sign * hy[i];
    zs[i] = k + sign * hz[i];
  }
  int* kept = s.kept.data();
  int count = 0;
  if (support) {
    // The voxel nearest to each source position, clamped into the volume (outside it the sample
    // is 0 anyway except within half a voxel, which the clamp keeps): clamped in float, so the
    // truncation is the floor, and vectorised.
    const float top_x = v.nx - 0.5f, top_y = v.ny - 0.5f, top_z = v.nz - 0.5f;
    if (v.count() <= static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      int* nearest = s.nearest.data();
      const int row_y = v.nx, slice = v.nx * v.ny;  // int offsets: the volume has < 2^31 voxels
#pragma omp simd
      for (int i = 0; i < n; ++i) {
        const int si = static_cast<int>(std::min(std::max(xs[i] + 0.5f, 0.0f), top_x));
        const int sj = static_cast<int>(std::min(std::max(ys[i] + 0.5f, 0.0f), top_y));
        const int sk = static_cast<int>(std::min(std::max(zs[i] + 0.5f, 0.0f), top_z));
        nearest[i] = si + row_y * sj + slice * sk;
      }
      // The next row's source positions lie about (next_dy, next_dz) voxels from this row's.
      // Its support row, and the one row of coefficients that no earlier row of the traversal
      // touched (the far corner of its taps: 2 rows and 2 slices on), are fetched while this
      // row is sampled: waiting on those loads was half of the sampling's time (measured
      // side by side, docs/correlation.md "Speed", seventh round).
      const long long last = static_cast<long long>(v.count()) - 1;
      const long long next = static_cast<long long>(next_dy) * row_y + static_cast<long long>(next_dz) * slice;
      // (Clamped into the volume: the pointers stay inside their arrays.)
      for (int i = 0; i < n; i += 64) __builtin_prefetch(support + std::clamp(nearest[i] + next, 0LL, last));
      if (interpolation == Interpolation::cubic_bspline) {
        const long long far = next + 2LL * row_y + 2LL * slice;
        for (int i = 0; i < n; i += 16) __builtin_prefetch(v.data + std::clamp(nearest[i] + far, 0LL, last));
      }
      for (int i = 0; i < n; ++i) {
        kept[count] = i;
        count += support[nearest[i]] != 0;
      }
    } else {  // a larger volume: the same with 64-bit offsets, not vectorised
      for (int i = 0; i < n; ++i) {
        const int si = static_cast<int>(std::min(std::max(xs[i] + 0.5f, 0.0f), top_x));
        const int sj = static_cast<int>(std::min(std::max(ys[i] + 0.5f, 0.0f), top_y));
        const int sk = static_cast<int>(std::min(std::max(zs[i] + 0.5f, 0.0f), top_z));
        kept[count] = i;
        count += support[v.linear(si, sj, sk)] != 0;
      }
    }
    std::fill(out, out + n, 0.0f);
  } else {
    for (int i = 0; i < n; ++i) kept[i] = i;
    count = n;
  }
  for (int m = 0; m < count; ++m) {
    const int i = kept[m];
    const float x = xs[i], y = ys[i], z = zs[i];
    if (interpolation == Interpolation::trilinear) {
      out[i] = sample_trilinear(v, x, y, z);
      continue;
    }
    const int ii = floor_int(x), jj = floor_int(y), kk = floor_int(z);
    if (ii >= 1 && jj >= 1 && kk >= 1 && ii + 2 < v.nx && jj + 2 < v.ny && kk + 2 < v.nz) {
      float wx[4], wy[4], wz[4];
      bspline_weights(x - ii, wx);
      bspline_weights(y - jj, wy);
      bspline_weights(z - kk, wz);
      out[i] = bspline_interior(v.data + v.linear(ii - 1, jj - 1, kk - 1), sy, sz, wx, wy, wz);
    } else {
      out[i] = sample_bspline(v, x, y, z);
    }
  }
  // The row's largest magnitude (the row is in cache): the deformed volume's, for its listing,
  // without another sweep over it.
  float largest = 0.0f;
#pragma omp simd reduction(max : largest)
  for (int i = 0; i < n; ++i) largest = std::max(largest, std::abs(out[i]));
  return largest;
}

}  // namespace

DeformedLargest deform_pair(const VolumeView& a, const VolumeView& b, const VectorField& predictor, int factor,
                            Interpolation interpolation, std::vector<float>& out_a, std::vector<float>& out_b,
                            int threads, const std::vector<std::uint8_t>& support_a,
                            const std::vector<std::uint8_t>& support_b) {
  // Every voxel is written below: size the (reused) buffers without clearing them first.
  out_a.resize(a.count());
  out_b.resize(b.count());
  const double offset = 0.5 * (factor - 1);  // full-grid position of a binned voxel's centre
  const float half = 0.5f / factor;           // half the displacement, in binned voxels
  const AxisCells cells = axis_cells(a.nx, factor, offset, predictor.origin.x, predictor.spacing.x, predictor.nx);
  const int nodes_x = predictor.nx;
  const std::uint8_t* mask_a = support_a.empty() ? nullptr : support_a.data();
  const std::uint8_t* mask_b = support_b.empty() ? nullptr : support_b.data();
  float largest_a = 0.0f, largest_b = 0.0f;
#pragma omp parallel num_threads(thread_count(threads)) reduction(max : largest_a, largest_b)
  {
  const FlushDenormals flush;
  RowPredictor along_row(predictor);  // the predictor's y-z interpolation once per row
  std::vector<float> hx(a.nx), hy(a.nx), hz(a.nx), column(3 * static_cast<std::size_t>(nodes_x));
  RowScratch scratch(a.nx);
  // Tiles of kTileRows rows in y run through every z: the 4 x (kTileRows + 3) coefficient rows
  // an output slice of a tile reads stay in cache for the next slices, so each coefficient is
  // fetched from memory about once (slice by slice, each was fetched 4 times).
  constexpr int kTileRows = 16;
  const int tiles = (a.ny + kTileRows - 1) / kTileRows;
#pragma omp for schedule(dynamic, 1)
  for (int tile = 0; tile < tiles; ++tile)
  for (int k = 0; k < a.nz; ++k)
    for (int j = tile * kTileRows; j < std::min(a.ny, (tile + 1) * kTileRows); ++j) {
      along_row.set_row(j * factor + offset, k * factor + offset);
      const double* c = along_row.columns();
      for (std::size_t m = 0; m < column.size(); ++m) column[m] = static_cast<float>(c[m]);
      // Half the predicted displacement at every voxel of the row, in voxels of this level.
      for (int i = 0; i < a.nx; ++i) {
        const int cell = cells.cell[i];
        const float* c0 = column.data() + 3 * static_cast<std::size_t>(cell);
        const float* c1 = nodes_x > 1 ? c0 + 3 : c0;
        const float f = cells.frac[i];
        hx[i] = (c0[0] + f * (c1[0] - c0[0])) * half;
        hy[i] = (c0[1] + f * (c1[1] - c0[1])) * half;
        hz[i] = (c0[2] + f * (c1[2] - c0[2])) * half;
      }
      const std::size_t row = a.linear(0, j, k);
      // The row after this one in the traversal: the next of the tile, or the tile's first of
      // the next slice.
      const int tile_last = std::min(a.ny, (tile + 1) * kTileRows) - 1;
      const int next_dy = j < tile_last ? 1 : tile * kTileRows - j, next_dz = j < tile_last ? 0 : 1;
      largest_a = std::max(largest_a, deform_row(a, mask_a, interpolation, j, k, -1.0f, hx.data(), hy.data(), hz.data(),
                                                 next_dy, next_dz, scratch, out_a.data() + row));
      largest_b = std::max(largest_b, deform_row(b, mask_b, interpolation, j, k, +1.0f, hx.data(), hy.data(), hz.data(),
                                                 next_dy, next_dz, scratch, out_b.data() + row));
    }
  }
  return {largest_a, largest_b};
}

}  // namespace tomorig::piv::detail
