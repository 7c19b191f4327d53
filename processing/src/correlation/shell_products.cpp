// face_products (direct_correlator.h): the wrapped lag products of every face entry, made once
// per deformation pass. A window that starts and ends on block borders pairs an entry on its
// low x face with b at x + W - 1 (the FFT's circular lag -1), whichever of the 16 windows at
// 75 % overlap that share this face plane it is; so the products A(x) B(partner) are the same
// for all of them and only the weights differ. Each window then adds weight x product per entry
// instead of reading b at 9 scattered places per entry (the largest item of the direct loop in
// `tomorig process`).
#include <omp.h>

#include "correlation/direct_correlator.h"

namespace tomorig::piv::detail {

void face_products(const OccupiedVoxels& oa, const VolumeView& vb, Int3 window, int threads, FaceProducts& out) {
  out.window = window;
  const int size[3] = {window.x, window.y, window.z};
  const int n[3] = {vb.nx, vb.ny, vb.nz};
  for (int f = 0; f < 6; ++f) {
    const int axis = f / 2;
    const bool high = f % 2;
    // The other two axes, in the order of the slots (x before y before z).
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    const std::vector<OccupiedVoxels::Entry>& entries = oa.face_entries[f];
    std::vector<float>& products = out.values[f];
    products.resize(entries.size() * kFaceSlots);
    const long long count = static_cast<long long>(entries.size());
#pragma omp parallel for num_threads(threads) schedule(static)
    for (long long e = 0; e < count; ++e) {
      const OccupiedVoxels::Entry& entry = entries[e];
      int c[3] = {entry.x, entry.y, entry.z};
      // The partner across the window along `axis`: the opposite face of the window whose low
      // (high) face this entry lies on.
      c[axis] += high ? -(size[axis] - 1) : size[axis] - 1;
      float* out_entry = products.data() + e * kFaceSlots;
      const bool along = c[axis] >= 0 && c[axis] < n[axis];
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          int p[3] = {c[0], c[1], c[2]};
          p[u] += du;
          p[v] += dv;
          const bool in = along && p[u] >= 0 && p[u] < n[u] && p[v] >= 0 && p[v] < n[v];
          out_entry[(du + 1) + 3 * (dv + 1)] = in ? entry.value * vb.data[vb.linear(p[0], p[1], p[2])] : 0.0f;
        }
    }
  }
}

}  // namespace tomorig::piv::detail
