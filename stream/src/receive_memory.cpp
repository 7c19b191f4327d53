#include "tomorig/stream/receive_memory.h"

#include <cstdlib>  // defines __GLIBC__ on glibc systems

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace tomorig::stream {

bool keep_receive_buffers() {
#if defined(__GLIBC__)
  // One arena: ZeroMQ's I/O thread allocates the parts and the consumer frees them; with
  // per-thread arenas the I/O thread's arena kept growing into fresh memory (measured on
  // loopback TCP: 4x the page faults per GB of the single arena). The mmap threshold at glibc's maximum (32 MiB)
  // serves camera-sized parts from the heap, and a trim threshold of 1 GiB keeps freed memory
  // mapped instead of handing it back to the kernel between sets.
  constexpr int kMmapThreshold = 32 << 20;
  constexpr int kTrimThreshold = 1 << 30;
  const bool arena = mallopt(M_ARENA_MAX, 1) == 1;
  const bool mmap = mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1;
  const bool trim = mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1;
  return arena && mmap && trim;
#else
  return false;
#endif
}

}  // namespace tomorig::stream
