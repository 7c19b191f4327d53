// keep_receive_buffers(): memory of received frame parts is reused instead of faulted in afresh.
// ZeroMQ's I/O thread allocates each part with malloc and the consumer frees it; this test
// plays that pattern with camera-sized blocks and counts the page faults of the second round.
// (The effect on the whole TCP path, timing-dependent, is measured by `tomorig bench stream`:
// page_faults_per_gb.) A program of its own, because the setting must be made before any
// thread allocates (glibc fixes its arena limit then), and other stream tests start threads.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

#include "tomorig/stream/receive_memory.h"

namespace tomorig::stream {
namespace {

long minor_page_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

constexpr std::size_t kPartBytes = (std::size_t{8} << 20) + 64;  // a 2048 x 2048 Mono16 frame and its header
constexpr int kPartsInFlight = 8;                                 // one set of 4 cameras x 2 frames

// Like ZeroMQ's receiving I/O thread: allocates the parts and writes into them.
std::vector<void*> receive_round() {
  std::vector<void*> parts;
  std::thread io([&] {
    for (int i = 0; i < kPartsInFlight; ++i) {
      void* p = std::malloc(kPartBytes);
      ASSERT_NE(p, nullptr);
      std::memset(p, i + 1, kPartBytes);
      parts.push_back(p);
    }
  });
  io.join();
  return parts;
}

TEST(ReceiveMemory, FreedPartsAreReusedWithoutPageFaults) {
#ifdef TOMORIG_SANITIZED
  // AddressSanitizer replaces glibc's malloc with its own, whose mallopt() accepts no setting:
  // there is no glibc allocator to measure here (the Release tree runs this test).
  GTEST_SKIP() << "glibc's allocator is replaced by the sanitizer's";
#endif
  ASSERT_TRUE(keep_receive_buffers()) << "the C library refused the allocator settings";
  for (void* p : receive_round()) std::free(p);  // the consumer drops the set: first round, fresh memory
  const long before = minor_page_faults();
  const std::vector<void*> second = receive_round();
  const long faults = minor_page_faults() - before;
  for (void* p : second) std::free(p);
  // 8 parts of 8 MiB are 16384 pages of 4 KiB. Fresh memory would fault in every one of them
  // (without the setting: each part its own mmap, unmapped again on free); reused memory none,
  // beyond the thread's stack.
  const long pages = static_cast<long>(kPartsInFlight * kPartBytes / 4096);
  EXPECT_LT(faults, pages / 100) << faults << " page faults writing " << pages << " pages of reused parts";
}

}  // namespace
}  // namespace tomorig::stream
