// The global operator new of core/src/large_page_new.cpp: large buffers start on a huge-page
// boundary and, where the kernel offers transparent huge pages, are backed by them; small ones
// and every kind of delete keep working.
#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;

std::string read_file(const char* path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// AnonHugePages (kB) of the mapping that contains `address`, from /proc/self/smaps.
long huge_kb_of_mapping(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    unsigned long lo = 0, hi = 0;
    if (std::sscanf(line.c_str(), "%lx-%lx ", &lo, &hi) == 2 && line.find(':') > line.find('-')) {
      inside = a >= lo && a < hi;
      continue;
    }
    long kb = 0;
    if (inside && std::sscanf(line.c_str(), "AnonHugePages: %ld kB", &kb) == 1) return kb;
  }
  return -1;
}

TEST(LargePageNew, LargeVectorsStartOnAHugePageBoundary) {
  std::vector<float> v(std::size_t{16} << 20);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kHugePage, 0u);
  v.assign(v.size(), 1.0f);
  EXPECT_EQ(v.back(), 1.0f);
}

TEST(LargePageNew, LargeVectorsUseHugePagesWhenTheKernelOffersThem) {
  const std::string mode = read_file("/sys/kernel/mm/transparent_hugepage/enabled");
  if (mode.find("[never]") != std::string::npos || mode.empty())
    GTEST_SKIP() << "transparent huge pages are off on this machine";
  std::vector<float> v(std::size_t{64} << 20, 2.0f);  // 256 MiB, touched
  EXPECT_GT(huge_kb_of_mapping(v.data()), 0) << "no AnonHugePages in the buffer's mapping";
}

TEST(LargePageNew, SmallAndArrayAndNothrowAllocationsRoundTrip) {
  auto small = std::make_unique<int>(7);
  EXPECT_EQ(*small, 7);
  auto array = std::make_unique<double[]>(std::size_t{3} << 20);  // 24 MiB through new[]
  array[0] = 1.5;
  EXPECT_EQ(array[0], 1.5);
  void* p = ::operator new(std::size_t{10} << 20, std::nothrow);
  ASSERT_NE(p, nullptr);
  ::operator delete(p, std::nothrow);
  void* zero = ::operator new(0);
  EXPECT_NE(zero, nullptr);
  ::operator delete(zero, std::size_t{0});
}

// aligned_alloc wants a size that is a multiple of its 2 MiB alignment (issue 14, defect 8:
// sanitizers abort otherwise): every large buffer gets whole huge pages, the same pages the
// huge-page advice covers, and a size that cannot be rounded up fails as bad_alloc.
TEST(LargePageNew, LargeBuffersAreWholeHugePages) {
  for (const std::size_t bytes : {std::size_t{1} << 20, (std::size_t{2} << 20) + 1, (std::size_t{3} << 20) + 123,
                                  (std::size_t{5} << 20) + 7, (std::size_t{9} << 20) + 4095}) {
    void* p = ::operator new(bytes);
    const std::size_t whole_pages = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % kHugePage, 0u) << bytes;
    EXPECT_GE(malloc_usable_size(p), whole_pages) << bytes << " bytes";
    ::operator delete(p);
  }
  volatile std::size_t huge = SIZE_MAX - 5;  // volatile: no compile-time "too large" diagnosis
  EXPECT_THROW(static_cast<void>(::operator new(huge)), std::bad_alloc);
  EXPECT_EQ(::operator new(huge, std::nothrow), nullptr);
}

}  // namespace
