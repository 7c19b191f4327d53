#pragma once
// exp() and log() for the multiplicative updates, inlined and branch-free: one exp per voxel
// and camera and one log per pixel and camera are, as libm calls, a large share of an
// iteration once the voxel list is pruned.
//
// fast_exp: 2^(x log2 e) split into an integer power (built in the exponent bits) and 2^f,
// f in [-0.5, 0.5], by a degree-6 polynomial. Relative error < 4e-6 for |x| <= 40 (mostly the
// float rounding of x log2 e), far below what an iteration changes. Arguments are clamped to
// [-87, 88] (float's normal range).
#include <cstdint>
#include <cstring>

namespace tomorig::recon::detail {

inline float fast_exp(float x) {
  x = x < -87.0f ? -87.0f : (x > 88.0f ? 88.0f : x);
  const float t = x * 1.44269504088896341f;  // log2(e)
  // Round to nearest by the 1.5 * 2^23 trick (no libm call, no SSE4.1 needed).
  const float shifted = t + 12582912.0f;
  const float n = shifted - 12582912.0f;
  const float f = t - n;  // [-0.5, 0.5]
  // 2^f = exp(f ln 2), Taylor in g = f ln 2 up to g^6.
  const float g = f * 0.693147180559945309f;
  float p = 1.0f / 720.0f;
  p = p * g + 1.0f / 120.0f;
  p = p * g + 1.0f / 24.0f;
  p = p * g + 1.0f / 6.0f;
  p = p * g + 0.5f;
  p = p * g + 1.0f;
  p = p * g + 1.0f;
  const std::int32_t e = static_cast<std::int32_t>(n) + 127;
  const std::uint32_t bits = static_cast<std::uint32_t>(e) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

// Natural log of a positive, normal float: x = m 2^e with m in [0.75, 1.5), and
// ln m = 2 atanh(s), s = (m - 1) / (m + 1), |s| < 0.2, by its odd series to s^9: relative
// error < 1e-7 in ln m, absolute < 2e-7 overall. Not for 0, denormals, inf or NaN.
inline float fast_log(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  // Exponent relative to 0.75: subtracting the bits of 0.75 puts m in [0.75, 1.5).
  const std::int32_t offset = static_cast<std::int32_t>(bits) - 0x3f400000;
  const std::int32_t e = offset >> 23;  // arithmetic shift: floor division by 2^23
  const std::uint32_t mbits = bits - (static_cast<std::uint32_t>(e) << 23);
  float m;
  std::memcpy(&m, &mbits, sizeof m);
  const float s = (m - 1.0f) / (m + 1.0f), s2 = s * s;
  float p = 1.0f / 9.0f;
  p = p * s2 + 1.0f / 7.0f;
  p = p * s2 + 1.0f / 5.0f;
  p = p * s2 + 1.0f / 3.0f;
  p = p * s2 + 1.0f;
  return static_cast<float>(e) * 0.693147180559945309f + 2.0f * s * p;
}

}  // namespace tomorig::recon::detail
