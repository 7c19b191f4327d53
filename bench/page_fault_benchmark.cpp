// First touch of fresh memory, the cost behind core/src/large_page_new.cpp: each iteration maps
// a new anonymous 256 MiB region, optionally advises huge pages, writes every byte once and
// unmaps it. Arguments: 0 = 4 KiB pages, 1 = MADV_HUGEPAGE. Compare with a second write of the
// same buffer (BM_RewriteTouched), which is the memory-bandwidth floor.
//
// In this VM a page fault traps to the hypervisor, so the 4 KiB case costs ~3.5 ms per MB; with
// huge pages the fault count drops 512-fold. The first huge-page round of a process can still be
// slow when the host has to back memory the guest has not used recently.
#include <benchmark/benchmark.h>
#include <sys/mman.h>

#include <cstring>

namespace {

constexpr std::size_t kBytes = std::size_t{256} << 20;

void BM_FirstTouch(benchmark::State& state) {
  const bool huge = state.range(0) != 0;
  for (auto _ : state) {
    void* p = mmap(nullptr, kBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) {
      state.SkipWithError("mmap failed");
      return;
    }
    if (huge) madvise(p, kBytes, MADV_HUGEPAGE);
    std::memset(p, 1, kBytes);
    benchmark::DoNotOptimize(p);
    benchmark::ClobberMemory();
    munmap(p, kBytes);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(kBytes));
}
BENCHMARK(BM_FirstTouch)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(4);

void BM_RewriteTouched(benchmark::State& state) {
  void* p = mmap(nullptr, kBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) {
    state.SkipWithError("mmap failed");
    return;
  }
  madvise(p, kBytes, MADV_HUGEPAGE);
  std::memset(p, 1, kBytes);
  for (auto _ : state) {
    std::memset(p, 2, kBytes);
    benchmark::DoNotOptimize(p);
    benchmark::ClobberMemory();
  }
  munmap(p, kBytes);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(kBytes));
}
BENCHMARK(BM_RewriteTouched)->Unit(benchmark::kMillisecond)->Iterations(4);

}  // namespace
