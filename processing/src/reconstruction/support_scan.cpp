#include "support_scan.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace tomorig::recon::detail {
namespace {

// One camera's reach test over the voxels [first, last) of a row (positions from the row's
// GridProjector::row_segments): writes every tested voxel's position to u, v (the arithmetic
// of GridProjector::row, a multiply then an add, so the same bits) and clears reachable[i]
// unless voxel i lies in the image span and in a reachable cell.
struct SegmentPass {
  const float *u0, *du, *v0, *dv;
  int segments, step;
  const std::uint32_t* bits;
  int stride;
  float u_max, v_max;
  float *u, *v;
  std::uint32_t* reachable;

  // Voxel i belongs to segment min(i / step, segments - 1): the last one runs on to the row's end.
  int segment_of(int i) const { return std::min(i / step, segments - 1); }
};

// Voxel i: its position (stored) and its reach bit (and-ed into reachable[i]).
// kClamp: a position outside the image span is moved onto its edge instead of failing the test
// (the coarse test of support_scan.h, where the point tested stands for a block of voxels).
template <bool kClamp = false>
inline void test_voxel(const SegmentPass& p, int i) {
  const int a = p.segment_of(i);
  const float off = static_cast<float>(i - a * p.step);
  const float uu = p.u0[a] + p.du[a] * off, vv = p.v0[a] + p.dv[a] * off;
  p.u[i] = uu;
  p.v[i] = vv;
  const float cu = std::min(std::max(uu, -0.5f), p.u_max), cv = std::min(std::max(vv, -0.5f), p.v_max);
  const std::uint32_t inside = kClamp ? 1u : static_cast<std::uint32_t>((cu == uu) & (cv == vv));
  const auto cell = static_cast<std::uint32_t>(static_cast<int>(cv + 1.0f) * p.stride + static_cast<int>(cu + 1.0f));
  p.reachable[i] &= inside & (p.bits[cell >> 5] >> (cell & 31u));
}

template <bool kClamp>
void reach_pass_scalar(const SegmentPass& p, int first, int last) {
  for (int i = first; i < last; ++i) test_voxel<kClamp>(p, i);
}

// The reach test of one camera for the listed voxels only (alive[0 .. count-1], ascending),
// with the dense passes' arithmetic. Used once few voxels are left, where a dense pass would
// test mostly dead ones.
void reach_list(const SegmentPass& p, const int* alive, int count) {
  for (int n = 0; n < count; ++n) test_voxel(p, alive[n]);
}

#if defined(__x86_64__)
// GCC 12's AVX-512 headers trip -Wmaybe-uninitialized on their own _mm512_undefined values.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// The same, 16 consecutive voxels at a time: one gather of the packed mask per 16 voxels. The
// 16 voxels may span several segments (the step is a power of two; coarse passes use steps of
// 8 and less), so each lane takes its segment's start and slope from a 16-entry window of the
// segment arrays. No contraction of the multiply and add into an FMA: the positions must be
// those of the scalar row().
template <bool kClamp>
__attribute__((target("avx512f"), optimize("fp-contract=off"))) void reach_pass_avx512(const SegmentPass& p, int first, int last) {
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m512 low = _mm512_set1_ps(-0.5f), u_max = _mm512_set1_ps(p.u_max), v_max = _mm512_set1_ps(p.v_max);
  const __m512 one = _mm512_set1_ps(1.0f);
  const __m512i stride = _mm512_set1_epi32(p.stride), low_bits = _mm512_set1_epi32(31), bit0 = _mm512_set1_epi32(1);
  const __m512i last_segment = _mm512_set1_epi32(p.segments - 1);
  const int shift = __builtin_ctz(static_cast<unsigned>(p.step));
  const __m512i step = _mm512_set1_epi32(p.step);
  for (int b = first; b < last; b += 16) {
    const __mmask16 m = last - b >= 16 ? static_cast<__mmask16>(0xFFFF) : static_cast<__mmask16>((1u << (last - b)) - 1u);
    // 16 voxels that an earlier camera already rejected: nothing to test, no position needed.
    const __m512i old = _mm512_maskz_loadu_epi32(m, p.reachable + b);
    const __mmask16 live = _mm512_test_epi32_mask(old, old);
    if (live == 0) continue;
    const __m512i i = _mm512_add_epi32(_mm512_set1_epi32(b), lane);
    const __m512i a = _mm512_min_epi32(_mm512_srli_epi32(i, static_cast<unsigned>(shift)), last_segment);
    const int a0 = p.segment_of(b);
    const __m512i window = _mm512_sub_epi32(a, _mm512_set1_epi32(a0));  // 0 .. 15
    const __mmask16 have = static_cast<__mmask16>(p.segments - a0 >= 16 ? 0xFFFF : (1u << (p.segments - a0)) - 1u);
    const __m512 pu = _mm512_permutexvar_ps(window, _mm512_maskz_loadu_ps(have, p.u0 + a0));
    const __m512 qu = _mm512_permutexvar_ps(window, _mm512_maskz_loadu_ps(have, p.du + a0));
    const __m512 pv = _mm512_permutexvar_ps(window, _mm512_maskz_loadu_ps(have, p.v0 + a0));
    const __m512 qv = _mm512_permutexvar_ps(window, _mm512_maskz_loadu_ps(have, p.dv + a0));
    const __m512 off = _mm512_cvtepi32_ps(_mm512_sub_epi32(i, _mm512_mullo_epi32(a, step)));
    const __m512 uu = _mm512_add_ps(pu, _mm512_mul_ps(qu, off));
    const __m512 vv = _mm512_add_ps(pv, _mm512_mul_ps(qv, off));
    _mm512_mask_storeu_ps(p.u + b, m, uu);
    _mm512_mask_storeu_ps(p.v + b, m, vv);
    const __m512 cu = _mm512_min_ps(_mm512_max_ps(uu, low), u_max);
    const __m512 cv = _mm512_min_ps(_mm512_max_ps(vv, low), v_max);
    const __mmask16 inside =
        kClamp ? live : _mm512_mask_cmp_ps_mask(live, cu, uu, _CMP_EQ_OQ) & _mm512_cmp_ps_mask(cv, vv, _CMP_EQ_OQ);
    const __m512i x = _mm512_cvttps_epi32(_mm512_add_ps(cu, one));
    const __m512i y = _mm512_cvttps_epi32(_mm512_add_ps(cv, one));
    const __m512i cell = _mm512_add_epi32(_mm512_mullo_epi32(y, stride), x);
    const __m512i word = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), inside, _mm512_srli_epi32(cell, 5),
                                                      p.bits, 4);
    const __m512i bit = _mm512_and_si512(_mm512_srlv_epi32(word, _mm512_and_si512(cell, low_bits)), bit0);
    _mm512_mask_storeu_epi32(p.reachable + b, m, _mm512_maskz_and_epi32(inside, old, bit));
  }
}

// The indices i in [first, last) with reachable[i] != 0, ascending, into alive; their count.
__attribute__((target("avx512f"))) int list_reachable_avx512(const std::uint32_t* reachable, int first, int last,
                                                             int* alive) {
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  int count = 0;
  for (int b = first; b < last; b += 16) {
    const __mmask16 m = last - b >= 16 ? static_cast<__mmask16>(0xFFFF) : static_cast<__mmask16>((1u << (last - b)) - 1u);
    const __m512i r = _mm512_maskz_loadu_epi32(m, reachable + b);
    const __mmask16 live = _mm512_test_epi32_mask(r, r);
    if (live == 0) continue;
    _mm512_mask_compressstoreu_epi32(alive + count, live, _mm512_add_epi32(_mm512_set1_epi32(b), lane));
    count += __builtin_popcount(live);
  }
  return count;
}
#pragma GCC diagnostic pop
#endif

std::atomic<bool> vector_pass_allowed{true};

// Survivors fewer than 1 / kSparseFactor of their span switch the later cameras to listed tests.
constexpr int kSparseFactor = 4;

bool vector_kernels() {
#if defined(__x86_64__)
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  return avx512 && vector_pass_allowed.load(std::memory_order_relaxed);
#else
  return false;
#endif
}

int list_reachable(const std::uint32_t* reachable, int first, int last, int* alive) {
#if defined(__x86_64__)
  if (vector_kernels()) return list_reachable_avx512(reachable, first, last, alive);
#endif
  int count = 0;
  for (int i = first; i < last; ++i) {
    alive[count] = i;
    count += static_cast<int>(reachable[i] != 0);
  }
  return count;
}

template <bool kClamp = false>
void reach_pass(const SegmentPass& p, int first, int last) {
#if defined(__x86_64__)
  if (vector_kernels()) return reach_pass_avx512<kClamp>(p, first, last);
#endif
  reach_pass_scalar<kClamp>(p, first, last);
}

// Narrows [first, last) to its first and last set flag; false if none is set.
bool trim_span(const std::uint32_t* flags, int& first, int& last) {
  while (first < last && flags[first] == 0) ++first;
  while (last > first && flags[last - 1] == 0) --last;
  return first < last;
}

// Once the survivors are a small part of their span, later cameras test the list instead of
// the span: a dense pass costs ~0.6 ns per voxel with AVX-512, a listed voxel a few ns. Lists
// the survivors into alive and returns their count if so, else -1.
int listed_if_sparse(const std::uint32_t* reachable, int first, int last, int* alive) {
  const int survivors = list_reachable(reachable, first, last, alive);
  return survivors * kSparseFactor < last - first ? survivors : -1;
}

// The padded reach mask of `image` dilated by r_u cells along x and r_v along y, packed.
std::vector<std::uint32_t> dilated_reach_bits(const ThresholdedImage& image, int r_u, int r_v) {
  const int w = image.stride, h = image.height + 2;
  std::vector<std::uint8_t> across(image.reach.size(), 0);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* in = image.reach.data() + static_cast<std::size_t>(y) * w;
    std::uint8_t* out = across.data() + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      std::uint8_t any = 0;
      for (int d = std::max(0, x - r_u), e = std::min(w - 1, x + r_u); d <= e; ++d) any |= in[d];
      out[x] = any;
    }
  }
  std::vector<std::uint32_t> bits((image.reach.size() + 31) / 32, 0u);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t any = 0;
      for (int d = std::max(0, y - r_v), e = std::min(h - 1, y + r_v); d <= e; ++d)
        any |= across[static_cast<std::size_t>(d) * w + x];
      const std::size_t n = static_cast<std::size_t>(y) * w + x;
      if (any) bits[n >> 5] |= 1u << (n & 31u);
    }
  return bits;
}

}  // namespace

void allow_vector_reach_pass(bool allow) { vector_pass_allowed.store(allow); }

ThresholdedImage::ThresholdedImage(const CameraImage& image, double threshold)
    : width(image.width), height(image.height), stride(image.width + 2) {
  pixels.assign(static_cast<std::size_t>(stride) * (height + 2), 0.0f);
  const float cut = static_cast<float>(threshold) * image.max;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float v = image.at(x, y);
      if (v > 0 && v >= cut) pixels[static_cast<std::size_t>(y + 1) * stride + x + 1] = v;
    }
  reach.assign(pixels.size(), 0);
  reach_bits.assign((pixels.size() + 31) / 32, 0u);
  std::size_t count = 0;
  for (int y = 0; y <= height; ++y)
    for (int x = 0; x <= width; ++x) {
      const float* p = pixels.data() + static_cast<std::size_t>(y) * stride + x;
      const bool any = p[0] > 0 || p[1] > 0 || p[stride] > 0 || p[stride + 1] > 0;
      const std::size_t n = static_cast<std::size_t>(y) * stride + x;
      reach[n] = any;
      if (any) reach_bits[n >> 5] |= 1u << (n & 31u);
      count += any;
    }
  reach_fraction = static_cast<double>(count) / (static_cast<double>(width + 1) * (height + 1));
}

SupportScanner::SupportScanner(const PreparedInput& in, const GridProjector& projector, double threshold)
    : projector_(projector), nx_(in.grid.nx) {
  images_.reserve(in.camera_count());
  for (const CameraImage& image : in.images) images_.emplace_back(image, threshold);
  // The most selective camera first: the later ones then test a shorter span, or nothing.
  order_.resize(images_.size());
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) {
    return images_[a].reach_fraction < images_[b].reach_fraction;
  });

  // Coarse test: the 8 voxels of a 2 x 2 x 2 block lie within half a voxel step along each
  // axis of the block's centre, so their images lie within rho = (|du/di| + |du/dj| +
  // |du/dk|) / 2 pixels of the centre's (likewise in v), and their cells within ceil(rho) cells
  // of the centre's cell. A block whose centre misses the reach mask dilated by that many cells
  // holds no reachable voxel.
  coarse_.resize(images_.size());
  for (std::size_t c = 0; c < images_.size(); ++c) {
    const GridProjector::Slopes s = projector_.slopes(c);
    if (!s.defined || projector_.step(c) < 2) continue;
    constexpr float kRoundingMargin = 1e-3f;  // float arithmetic of the positions, pixels
    const float rho_u = 0.5f * (s.u[0] + s.u[1] + s.u[2]) + kRoundingMargin;
    const float rho_v = 0.5f * (s.v[0] + s.v[1] + s.v[2]) + kRoundingMargin;
    const int r_u = static_cast<int>(std::ceil(rho_u)), r_v = static_cast<int>(std::ceil(rho_v));
    if (r_u > kMaxCoarseRadius || r_v > kMaxCoarseRadius) continue;  // too blunt to reject anything
    coarse_[c].bits = dilated_reach_bits(images_[c], r_u, r_v);
    coarse_[c].enabled = true;
    any_coarse_ = true;
  }
}

SupportScanner::Row SupportScanner::make_row() const {
  Row row;
  const std::size_t nx = static_cast<std::size_t>(nx_);
  row.u.resize(nx * images_.size());
  row.v.resize(nx * images_.size());
  row.product.resize(nx);
  row.alive.resize(nx);
  row.reachable.resize(nx);
  const std::size_t segments = static_cast<std::size_t>(projector_.max_segments());
  row.u0.resize(segments);
  row.du.resize(segments);
  row.v0.resize(segments);
  row.dv.resize(segments);
  row.tested.assign(images_.size(), 0);
  if (any_coarse_) {
    const std::size_t blocks = static_cast<std::size_t>(coarse_nx());
    row.coarse.assign(kCoarseRows * blocks, 0u);
    row.coarse_voxels.assign(kCoarseRows * nx, 0u);
    row.coarse_key.assign(kCoarseRows, -1);
    row.coarse_span.assign(2 * kCoarseRows, 0);
    row.coarse_u.resize(blocks);
    row.coarse_v.resize(blocks);
    row.centre_segments.resize(4 * segments);
  }
  return row;
}

int SupportScanner::coarse_nx() const { return (nx_ + 1) / 2; }

// The blocks (2I .. 2I+1, 2J .. 2J+1, 2K .. 2K+1) of super-row (J, K) that may hold a voxel
// reachable in every camera: 1 per block, 0 where some camera's dilated mask rules it out.
// Computed once per super-row and thread (a small cache keyed by J and K).
SupportScanner::CoarseRow SupportScanner::coarse_row(int big_j, int big_k, Row& row) const {
  const std::size_t slot = static_cast<std::size_t>(big_k) % kCoarseRows;
  const std::size_t blocks = static_cast<std::size_t>(coarse_nx());
  std::uint32_t* mask = row.coarse.data() + slot * blocks;
  const long long key = static_cast<long long>(big_j) * (1LL << 32) + big_k;
  if (row.coarse_key[slot] == key)
    return {row.coarse_voxels.data() + slot * static_cast<std::size_t>(nx_), row.coarse_span[2 * slot],
            row.coarse_span[2 * slot + 1]};
  row.coarse_key[slot] = key;
  std::fill(mask, mask + blocks, 1u);
  // The block centres lie half-way between the block's rows and slices (on the row itself
  // where the grid ends in a lone row or slice), at i = 2I + 1/2.
  const int ny = projector_.grid().ny, nz = projector_.grid().nz;
  const float dj = 2 * big_j + 1 < ny ? 0.5f : 0.0f, dk = 2 * big_k + 1 < nz ? 0.5f : 0.0f;
  const std::size_t segs = static_cast<std::size_t>(projector_.max_segments());
  float* u0 = row.centre_segments.data();
  float *du = u0 + segs, *v0 = u0 + 2 * segs, *dv = u0 + 3 * segs;
  int first = 0, last = static_cast<int>(blocks);
  for (const std::size_t c : order_) {
    if (!coarse_[c].enabled) continue;
    const int segments = projector_.row_segments(c, 2 * big_j, 2 * big_k, dj, dk, u0, du, v0, dv);
    for (int a = 0; a < segments; ++a) {
      u0[a] += 0.5f * du[a];  // offset 1/2 along i
      v0[a] += 0.5f * dv[a];
      du[a] *= 2.0f;  // two voxels per block
      dv[a] *= 2.0f;
    }
    const ThresholdedImage& im = images_[c];
    const int step = projector_.step(c) / 2;
    SegmentPass pass{u0, du, v0, dv, segments, step, coarse_[c].bits.data(), im.stride,
                     static_cast<float>(im.width) - 0.5f, static_cast<float>(im.height) - 0.5f, row.coarse_u.data(),
                     row.coarse_v.data(), mask};
    reach_pass<true>(pass, first, last);
    if (!trim_span(mask, first, last)) break;
  }
  // Spread to the row's voxels once, for the four rows of the super-row to copy.
  const int fine_first = 2 * first, fine_last = std::min(nx_, 2 * last);
  std::uint32_t* fine = row.coarse_voxels.data() + slot * static_cast<std::size_t>(nx_);
  for (int i = fine_first; i < fine_last; ++i) fine[i] = mask[i >> 1];
  row.coarse_span[2 * slot] = fine_first;
  row.coarse_span[2 * slot + 1] = fine_last;
  return {fine, fine_first, fine_last};
}

int SupportScanner::scan(int j, int k, Row& row) const {
  const std::size_t nx = static_cast<std::size_t>(nx_);
  std::uint32_t* reachable = row.reachable.data();
  int first = 0, last = nx_;
  int* alive = row.alive.data();
  int listed = -1;  // >= 0: the survivors are listed in alive[0 .. listed-1] (sparse passes)
  if (any_coarse_) {
    // The span comes trimmed: its first and last blocks may hold survivors.
    const CoarseRow coarse = coarse_row(j / 2, k / 2, row);
    first = coarse.first;
    last = coarse.last;
    if (first == last) return 0;
    std::copy(coarse.mask + first, coarse.mask + last, reachable + first);
    listed = listed_if_sparse(reachable, first, last, alive);
  } else {
    std::fill(reachable, reachable + nx, 1u);
  }
  for (std::size_t o = 0; o < order_.size(); ++o) {
    const std::size_t c = order_[o];
    const ThresholdedImage& im = images_[c];
    float* uc = row.u.data() + c * nx;
    float* vc = row.v.data() + c * nx;
    SegmentPass pass{row.u0.data(), row.du.data(), row.v0.data(), row.dv.data(), 0, projector_.step(c),
                     im.reach_bits.data(), im.stride, static_cast<float>(im.width) - 0.5f,
                     static_cast<float>(im.height) - 0.5f, uc, vc, reachable};
    pass.segments = projector_.row_segments(c, j, k, row.u0.data(), row.du.data(), row.v0.data(), row.dv.data());
    if (listed >= 0) {
      // Sparse: test only the listed survivors, then drop the ones this camera rejects.
      if (pass.segments > 0) {
        reach_list(pass, alive, listed);
      } else {
        projector_.row_at(c, j, k, alive, listed, uc, vc);
        for (int n = 0; n < listed; ++n) {
          const int i = alive[n];
          reachable[i] &= static_cast<std::uint32_t>(im.in_span(uc[i], vc[i]) && im.reach[im.cell(uc[i], vc[i])]);
        }
      }
      row.tested[o] += static_cast<std::uint64_t>(listed);
      int kept = 0;
      for (int n = 0; n < listed; ++n) {
        alive[kept] = alive[n];
        kept += static_cast<int>(reachable[alive[n]] != 0);
      }
      listed = kept;
      if (listed == 0) return 0;
      continue;
    }
    if (pass.segments > 0) {
      reach_pass(pass, first, last);
    } else {  // exact projection: the whole row, tested voxel by voxel
      projector_.row(c, j, k, uc, vc);
      for (int i = first; i < last; ++i)
        reachable[i] &= static_cast<std::uint32_t>(im.in_span(uc[i], vc[i]) && im.reach[im.cell(uc[i], vc[i])]);
    }
    row.tested[o] += static_cast<std::uint64_t>(last - first);
    if (!trim_span(reachable, first, last)) return 0;
    if (o + 1 < order_.size()) listed = listed_if_sparse(reachable, first, last, alive);
  }
  // Voxels reachable in every camera: read them, keep those whose reads are all > 0.
  float* product = row.product.data();
  const int count = listed >= 0 ? listed : list_reachable(reachable, first, last, alive);
  row.reached += static_cast<std::uint64_t>(count);
  int kept = 0;
  for (int n = 0; n < count; ++n) {
    const int i = alive[n];
    float p = 1.0f;
    bool lit = true;
    for (const std::size_t c : order_) {
      const std::size_t at = c * nx + static_cast<std::size_t>(i);
      const float s = images_[c].sample(row.u[at], row.v[at]);
      p *= s;
      lit = lit && s > 0.0f;
    }
    product[i] = p;
    alive[kept] = i;
    kept += lit;
  }
  return kept;
}

}  // namespace tomorig::recon::detail
