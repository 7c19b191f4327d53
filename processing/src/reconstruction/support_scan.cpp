#include "support_scan.h"

#include <algorithm>
#include <atomic>
#include <numeric>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace tomorig::recon::detail {
namespace {

// One camera's reach test over the segments [a_first, a_last) of a row (GridProjector::
// row_segments): writes every voxel's position to u, v (the arithmetic of GridProjector::row,
// a multiply then an add, so the same bits) and clears reachable[i] unless voxel i lies in the
// image span and in a reachable cell.
struct SegmentPass {
  const float *u0, *du, *v0, *dv;
  int segments, step, nx;
  const std::uint32_t* bits;
  int stride;
  float u_max, v_max;
  float *u, *v;
  std::uint32_t* reachable;

  int end_of(int a) const { return a == segments - 1 ? nx : std::min(a * step + step, nx); }
};

// Voxel i of segment a: its position (stored) and its reach bit (and-ed into reachable[i]).
inline void test_voxel(const SegmentPass& p, int a, int i) {
  const float off = static_cast<float>(i - a * p.step);
  const float uu = p.u0[a] + p.du[a] * off, vv = p.v0[a] + p.dv[a] * off;
  p.u[i] = uu;
  p.v[i] = vv;
  const float cu = std::min(std::max(uu, -0.5f), p.u_max), cv = std::min(std::max(vv, -0.5f), p.v_max);
  const std::uint32_t inside = (cu == uu) & (cv == vv);
  const auto cell = static_cast<std::uint32_t>(static_cast<int>(cv + 1.0f) * p.stride + static_cast<int>(cu + 1.0f));
  p.reachable[i] &= inside & (p.bits[cell >> 5] >> (cell & 31u));
}

void reach_pass_scalar(const SegmentPass& p, int a_first, int a_last) {
  for (int a = a_first; a < a_last; ++a)
    for (int i = a * p.step, i1 = p.end_of(a); i < i1; ++i) test_voxel(p, a, i);
}

// The reach test of one camera for the listed voxels only (alive[0 .. count-1], ascending),
// with the dense passes' arithmetic: voxel i belongs to segment min(i / step, segments - 1).
// Used once few voxels are left, where a dense pass would test mostly dead ones.
void reach_list(const SegmentPass& p, const int* alive, int count) {
  for (int n = 0; n < count; ++n) test_voxel(p, std::min(alive[n] / p.step, p.segments - 1), alive[n]);
}

#if defined(__x86_64__)
// GCC 12's AVX-512 headers trip -Wmaybe-uninitialized on their own _mm512_undefined values.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// The same, 16 voxels at a time: one gather of the packed mask per 16 voxels. No contraction of
// the multiply and add into an FMA: the positions must be those of the scalar row().
__attribute__((target("avx512f"), optimize("fp-contract=off"))) void reach_pass_avx512(const SegmentPass& p, int a_first, int a_last) {
  const __m512 lane = _mm512_setr_ps(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m512 low = _mm512_set1_ps(-0.5f), u_max = _mm512_set1_ps(p.u_max), v_max = _mm512_set1_ps(p.v_max);
  const __m512 one = _mm512_set1_ps(1.0f);
  const __m512i stride = _mm512_set1_epi32(p.stride), low_bits = _mm512_set1_epi32(31), bit0 = _mm512_set1_epi32(1);
  for (int a = a_first; a < a_last; ++a) {
    const int i0 = a * p.step, i1 = p.end_of(a);
    const __m512 pu = _mm512_set1_ps(p.u0[a]), qu = _mm512_set1_ps(p.du[a]);
    const __m512 pv = _mm512_set1_ps(p.v0[a]), qv = _mm512_set1_ps(p.dv[a]);
    for (int b = i0; b < i1; b += 16) {
      const __mmask16 m = i1 - b >= 16 ? static_cast<__mmask16>(0xFFFF) : static_cast<__mmask16>((1u << (i1 - b)) - 1u);
      // 16 voxels that an earlier camera already rejected: nothing to test, no position needed.
      const __m512i old = _mm512_maskz_loadu_epi32(m, p.reachable + b);
      const __mmask16 live = _mm512_test_epi32_mask(old, old);
      if (live == 0) continue;
      const __m512 off = _mm512_add_ps(_mm512_set1_ps(static_cast<float>(b - i0)), lane);
      const __m512 uu = _mm512_add_ps(pu, _mm512_mul_ps(qu, off));
      const __m512 vv = _mm512_add_ps(pv, _mm512_mul_ps(qv, off));
      _mm512_mask_storeu_ps(p.u + b, m, uu);
      _mm512_mask_storeu_ps(p.v + b, m, vv);
      const __m512 cu = _mm512_min_ps(_mm512_max_ps(uu, low), u_max);
      const __m512 cv = _mm512_min_ps(_mm512_max_ps(vv, low), v_max);
      const __mmask16 inside = _mm512_mask_cmp_ps_mask(live, cu, uu, _CMP_EQ_OQ) & _mm512_cmp_ps_mask(cv, vv, _CMP_EQ_OQ);
      const __m512i x = _mm512_cvttps_epi32(_mm512_add_ps(cu, one));
      const __m512i y = _mm512_cvttps_epi32(_mm512_add_ps(cv, one));
      const __m512i cell = _mm512_add_epi32(_mm512_mullo_epi32(y, stride), x);
      const __m512i word = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), inside, _mm512_srli_epi32(cell, 5),
                                                        p.bits, 4);
      const __m512i bit = _mm512_and_si512(_mm512_srlv_epi32(word, _mm512_and_si512(cell, low_bits)), bit0);
      _mm512_mask_storeu_epi32(p.reachable + b, m, _mm512_maskz_and_epi32(inside, old, bit));
    }
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

void reach_pass(const SegmentPass& p, int a_first, int a_last) {
#if defined(__x86_64__)
  if (vector_kernels()) return reach_pass_avx512(p, a_first, a_last);
#endif
  reach_pass_scalar(p, a_first, a_last);
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
  return row;
}

int SupportScanner::scan(int j, int k, Row& row) const {
  const std::size_t nx = static_cast<std::size_t>(nx_);
  std::uint32_t* reachable = row.reachable.data();
  std::fill(reachable, reachable + nx, 1u);
  int first = 0, last = nx_;
  int* alive = row.alive.data();
  int listed = -1;  // >= 0: the survivors are listed in alive[0 .. listed-1] (sparse passes)
  for (std::size_t o = 0; o < order_.size(); ++o) {
    const std::size_t c = order_[o];
    const ThresholdedImage& im = images_[c];
    float* uc = row.u.data() + c * nx;
    float* vc = row.v.data() + c * nx;
    SegmentPass pass{row.u0.data(), row.du.data(), row.v0.data(), row.dv.data(), 0, projector_.step(c), nx_,
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
      const int a_first = std::min(first / pass.step, pass.segments - 1);
      const int a_last = std::min((last - 1) / pass.step, pass.segments - 1) + 1;
      reach_pass(pass, a_first, a_last);
    } else {  // exact projection: the whole row, tested voxel by voxel
      projector_.row(c, j, k, uc, vc);
      for (int i = first; i < last; ++i)
        reachable[i] &= static_cast<std::uint32_t>(im.in_span(uc[i], vc[i]) && im.reach[im.cell(uc[i], vc[i])]);
    }
    row.tested[o] += static_cast<std::uint64_t>(last - first);
    while (first < last && reachable[first] == 0) ++first;
    while (last > first && reachable[last - 1] == 0) --last;
    if (first == last) return 0;
    // Once the survivors are a small part of their span, later cameras test the list instead
    // of the span: a dense pass costs ~0.6 ns per voxel with AVX-512, a listed voxel a few ns.
    if (o + 1 < order_.size()) {
      const int survivors = list_reachable(reachable, first, last, alive);
      if (survivors * kSparseFactor < last - first) listed = survivors;
    }
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
