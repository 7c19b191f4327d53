// Replacement of the global allocation functions: allocations of kLargeAllocationBytes and
// more start on a 2 MiB boundary and are marked MADV_HUGEPAGE.
//
// Why: on this machine class (a paravirtualised VM, transparent huge pages in "madvise" mode)
// every first touch of a 4 KiB page traps to the hypervisor. Measured here: writing a fresh
// 256 MiB buffer takes 0.90 s with 4 KiB pages and 0.023 s with huge pages (docs/performance.md,
// "Page faults"). tomorig's volumes, sparse systems and frame sets are
// exactly such buffers, allocated once per set and written once, so without this the memory
// floor, not the arithmetic, sets the speed of reconstruction and correlation.
//
// Linked into the executables (tomorig, benchmarks, tests) as an object library, not into the
// module libraries, so a program embedding the libraries keeps its own allocator.
#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

namespace {

constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;
// Below this a huge page would be mostly empty; the small-object heap serves it as before.
constexpr std::size_t kLargeAllocationBytes = std::size_t{1} << 20;

void* allocate(std::size_t bytes) noexcept {
  if (bytes >= kLargeAllocationBytes) {
    // aligned_alloc wants a size that is a multiple of the alignment (C11; glibc is lenient,
    // sanitizers are not), so the buffer is rounded up to whole huge pages. That is also what
    // the advice below covers: a 4 KiB-page tail would cost up to 2 MiB of slow faults per
    // buffer; the price is at most 2 MiB of address space (resident once touched) per buffer.
    if (bytes > SIZE_MAX - (kHugePageBytes - 1)) return nullptr;  // rounding would wrap: no such buffer
    const std::size_t rounded = (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
    if (void* p = std::aligned_alloc(kHugePageBytes, rounded)) {
      // Advice only: if the kernel has no huge pages to give, the memory is still valid.
      madvise(p, rounded, MADV_HUGEPAGE);
      return p;
    }
  }
  return std::malloc(bytes == 0 ? 1 : bytes);
}

void* allocate_or_throw(std::size_t bytes) {
  for (;;) {
    if (void* p = allocate(bytes)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

}  // namespace

void* operator new(std::size_t bytes) { return allocate_or_throw(bytes); }
void* operator new[](std::size_t bytes) { return allocate_or_throw(bytes); }
void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept { return allocate(bytes); }
void* operator new[](std::size_t bytes, const std::nothrow_t&) noexcept { return allocate(bytes); }
// Memory from aligned_alloc and malloc alike goes back through free().
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
