#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "decode.h"

namespace tomorig::config::detail {

void decode_grid(TableReader& root, GridConfig& grid) {
  auto r = root.table("grid");
  if (!r) return;
  const bool nx = valid_or_absent(*r, "nx", r->read("nx", grid.nx, Need::optional, greater_than(0)));
  const bool ny = valid_or_absent(*r, "ny", r->read("ny", grid.ny, Need::optional, greater_than(0)));
  const bool nz = valid_or_absent(*r, "nz", r->read("nz", grid.nz, Need::optional, greater_than(0)));
  r->read("voxel_size_mm", grid.voxel_size_mm, Need::optional, greater_than(0.0));
  r->read_numbers("origin_mm", grid.origin_mm);
  // Sparse volumes index voxels with 32 bits (core/volume.h).
  if (nx && ny && nz) {
    const std::uint64_t count = static_cast<std::uint64_t>(grid.nx) * static_cast<std::uint64_t>(grid.ny) *
                                static_cast<std::uint64_t>(grid.nz);
    if (count > std::numeric_limits<std::uint32_t>::max()) {
      r->issue("nz", fmt::format("nx * ny * nz = {} voxels exceeds the supported {}", count,
                                 std::numeric_limits<std::uint32_t>::max()));
    }
  }
  r->report_unknown_keys();
}

}  // namespace tomorig::config::detail
