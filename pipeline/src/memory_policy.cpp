#include "memory_policy.h"

#include <fstream>
#include <string>

namespace tomorig::pipeline {

double bytes_per_set_in_flight(const VoxelGrid& grid) {
  return 12.0 * static_cast<double>(grid.voxel_count()) * sizeof(float);
}

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024.0;
  return 0.0;
}

bool overlap_fits(const VoxelGrid& grid, double available) { return available > 2.0 * bytes_per_set_in_flight(grid); }

}  // namespace tomorig::pipeline
