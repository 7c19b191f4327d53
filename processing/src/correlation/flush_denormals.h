#pragma once
// Scoped flush-to-zero / denormals-are-zero for the calling thread. The recursive B-spline
// prefilter lets its ringing decay geometrically (pole^k) through the empty regions of a sparse
// volume down to subnormal floats, and arithmetic on subnormals is many times slower on x86;
// values that small (< 1e-38) carry no information for the correlation.
#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#endif

namespace tomorig::piv::detail {

class FlushDenormals {
 public:
#if defined(__SSE__) || defined(__x86_64__)
  FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }  // FTZ | DAZ
  ~FlushDenormals() { _mm_setcsr(saved_); }
#else
  FlushDenormals() = default;
#endif
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
#if defined(__SSE__) || defined(__x86_64__)
  unsigned saved_;
#endif
};

}  // namespace tomorig::piv::detail
