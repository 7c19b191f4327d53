#pragma once
// Whether the back-end may keep two sets in flight (one reconstructing, one correlating): they
// need about twice the dense volumes of one set, the correlator's float copies, deformed volumes
// and spline coefficients of both exposures (~8 dense volumes) plus the reconstruction's working
// volumes (~4). Overlap only when MemAvailable holds both with room to spare.
#include "tomorig/core/volume.h"

namespace tomorig::pipeline {

// Bytes one set in flight needs on `grid`.
double bytes_per_set_in_flight(const VoxelGrid& grid);
// MemAvailable from /proc/meminfo, bytes; 0 if unknown.
double available_memory_bytes();
// True if two sets fit in `available` bytes.
bool overlap_fits(const VoxelGrid& grid, double available);

}  // namespace tomorig::pipeline
