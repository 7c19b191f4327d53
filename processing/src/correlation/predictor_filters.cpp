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
  const int dims[3] = {field.nx, field.ny, field.nz};
  const std::size_t strides[3] = {1, static_cast<std::size_t>(field.nx),
                                  static_cast<std::size_t>(field.nx) * field.ny};
  std::vector<Vec3f> source;
  for (int axis = 0; axis < 3; ++axis) {
    if (dims[axis] < 2) continue;
    source = field.displacement;
    for (int k = 0; k < field.nz; ++k)
      for (int j = 0; j < field.ny; ++j)
        for (int i = 0; i < field.nx; ++i) {
          const int pos[3] = {i, j, k};
          const std::size_t n = field.linear(i, j, k);
          float weight = 2.0f;
          Vec3f sum{2.0f * source[n].x, 2.0f * source[n].y, 2.0f * source[n].z};
          if (pos[axis] > 0) {
            const Vec3f& v = source[n - strides[axis]];
            sum = {sum.x + v.x, sum.y + v.y, sum.z + v.z};
            weight += 1.0f;
          }
          if (pos[axis] < dims[axis] - 1) {
            const Vec3f& v = source[n + strides[axis]];
            sum = {sum.x + v.x, sum.y + v.y, sum.z + v.z};
            weight += 1.0f;
          }
          field.displacement[n] = {sum.x / weight, sum.y / weight, sum.z / weight};
        }
  }
}

}  // namespace tomorig::piv::detail
