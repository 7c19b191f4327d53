#include "correlation/predictor_filters.h"

#include <vector>

namespace tomorig::piv::detail {

void fill_invalid(VectorField& field) {
  std::vector<std::uint8_t> known(field.count());
  std::size_t missing = 0;
  for (std::size_t n = 0; n < field.count(); ++n) {
    known[n] = field.status[n] != VectorStatus::invalid;
    missing += !known[n];
  }
  while (missing > 0) {
    std::vector<std::uint8_t> next = known;
    std::size_t filled = 0;
    for (int k = 0; k < field.nz; ++k)
      for (int j = 0; j < field.ny; ++j)
        for (int i = 0; i < field.nx; ++i) {
          const std::size_t n = field.linear(i, j, k);
          if (known[n]) continue;
          double sum[3] = {0, 0, 0};
          int count = 0;
          for (int dk = -1; dk <= 1; ++dk)
            for (int dj = -1; dj <= 1; ++dj)
              for (int di = -1; di <= 1; ++di) {
                const int x = i + di, y = j + dj, z = k + dk;
                if (x < 0 || y < 0 || z < 0 || x >= field.nx || y >= field.ny || z >= field.nz) continue;
                const std::size_t m = field.linear(x, y, z);
                if (!known[m]) continue;
                sum[0] += field.displacement[m].x;
                sum[1] += field.displacement[m].y;
                sum[2] += field.displacement[m].z;
                ++count;
              }
          if (count == 0) continue;
          field.displacement[n] = {static_cast<float>(sum[0] / count), static_cast<float>(sum[1] / count),
                                   static_cast<float>(sum[2] / count)};
          next[n] = 1;
          ++filled;
        }
    known.swap(next);
    if (filled == 0) {
      for (std::size_t n = 0; n < field.count(); ++n)
        if (!known[n]) field.displacement[n] = {};
      break;
    }
    missing -= filled;
  }
}

void smooth_gaussian3(VectorField& field) {
  // (1 2 1)/4 per axis. At the first and last node of an axis the missing neighbour is the
  // linear extrapolation 2 u_0 - u_1, which leaves the end node as it is: renormalising to
  // (2 u_0 + u_1)/3 instead would pull the end nodes towards their inner neighbour, a bias of
  // a third of the node-to-node difference wherever the flow has a gradient at the boundary,
  // which the next deformation pass then feeds into the interior.
  const int dims[3] = {field.nx, field.ny, field.nz};
  const std::size_t strides[3] = {1, static_cast<std::size_t>(field.nx),
                                  static_cast<std::size_t>(field.nx) * field.ny};
  std::vector<Vec3f> source;
  for (int axis = 0; axis < 3; ++axis) {
    if (dims[axis] < 3) continue;
    source = field.displacement;
    for (int k = 0; k < field.nz; ++k)
      for (int j = 0; j < field.ny; ++j)
        for (int i = 0; i < field.nx; ++i) {
          const int pos[3] = {i, j, k};
          if (pos[axis] == 0 || pos[axis] == dims[axis] - 1) continue;
          const std::size_t n = field.linear(i, j, k);
          const Vec3f& l = source[n - strides[axis]];
          const Vec3f& c = source[n];
          const Vec3f& r = source[n + strides[axis]];
          field.displacement[n] = {0.25f * (l.x + 2.0f * c.x + r.x), 0.25f * (l.y + 2.0f * c.y + r.y),
                                   0.25f * (l.z + 2.0f * c.z + r.z)};
        }
  }
}

}  // namespace tomorig::piv::detail
