#pragma once
// Two loops of an FFT window correlation besides the transforms: the spectrum product and the
// search for the correlation peak. Each is compiled for AVX-512, AVX2 and the baseline (chosen
// at run time): in the default x86-64 build the peak search was a scalar chain of `maxss`, one
// comparison per value, and cost a third of the window's time outside FFTW.
#include <cstddef>

namespace tomorig::piv::detail {

// fa (interleaved complex, `count` values) becomes conj(fa) * fb.
void spectrum_product(float* fa, const float* fb, std::size_t count);

// Index of the first highest value of p[0, n) (NaN values are never chosen), n if there is none.
std::size_t first_maximum(const float* p, std::size_t n);

}  // namespace tomorig::piv::detail
