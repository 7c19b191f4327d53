#pragma once
// OpenMP thread counts for the simulator's parallel loops. Results never depend on the
// count: each loop writes disjoint outputs (rows, particles) in a fixed order.
#include <omp.h>

namespace tomorig::sim::detail {

// `requested` threads, or the OpenMP default when requested <= 0.
inline int thread_count(int requested) { return requested > 0 ? requested : omp_get_max_threads(); }

}  // namespace tomorig::sim::detail
