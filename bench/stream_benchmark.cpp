// Streaming throughput for the thesis-scale rig: sets of 4 cameras x 2 exposures x 2048^2
// Mono16 (64 MiB) over ZeroMQ PUSH/PULL on loopback TCP and inproc, next to a plain memcpy of
// the same bytes in the same run, so the ratio stream/memcpy can be stated. The target is the
// thesis rig's 4 x 2560 x 2160 x 2 x 2 B x 25 Hz = 2.2 GB/s.
//   build/bench/stream_benchmark --benchmark_format=json
#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <cstring>
#include <thread>
#include <vector>

#include <zmq.hpp>

#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/receive_memory.h"

namespace {
using namespace std::chrono_literals;

// As `tomorig record` does, before main() starts any thread: received parts reuse freed
// memory instead of fresh pages.
const bool kept_receive_buffers = tomorig::stream::keep_receive_buffers();

constexpr int kCameras = 4;
constexpr int kSide = 2048;

tomorig::FrameSet thesis_scale_set() {
  tomorig::FrameSet set;
  set.dt_ns = 10'000;
  for (int c = 0; c < kCameras; ++c) {
    tomorig::CameraFrames cam;
    cam.camera_id = "cam" + std::to_string(c);
    for (tomorig::Frame* f : {&cam.a, &cam.b}) {
      f->image = tomorig::Image::allocate(kSide, kSide, tomorig::SampleType::u16);
      for (int y = 0; y < kSide; ++y)  // non-zero pages, so nothing is backed by the zero page
        for (int x = 0; x < kSide; ++x) f->image.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(x ^ y ^ c);
    }
    set.cameras.push_back(std::move(cam));
  }
  return set;
}

std::int64_t set_bytes(const tomorig::FrameSet& set) {
  std::int64_t n = 0;
  for (const auto& cam : set.cameras) n += static_cast<std::int64_t>(cam.a.image.size_bytes() + cam.b.image.size_bytes());
  return n;
}

// CPU time of the whole process (all threads, ZeroMQ's I/O threads included). On a shared
// machine wall-clock rates depend on the load; bytes per CPU-second say what the path costs.
double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void report_cpu_cost(benchmark::State& state, double cpu_seconds, std::int64_t bytes) {
  state.counters["GB_per_cpu_second"] = cpu_seconds > 0 ? static_cast<double>(bytes) / cpu_seconds / 1e9 : 0.0;
}

const tomorig::FrameSet& shared_set() {
  static const tomorig::FrameSet set = thesis_scale_set();
  return set;
}

// The floor to compare with: copying every frame of a set once.
void BM_MemcpySet(benchmark::State& state) {
  const tomorig::FrameSet& set = shared_set();
  std::vector<std::vector<std::byte>> out(2 * kCameras, std::vector<std::byte>(kSide * kSide * 2, std::byte{1}));
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    for (int c = 0; c < kCameras; ++c) {
      std::memcpy(out[2 * c].data(), set.cameras[c].a.image.data(), out[2 * c].size());
      std::memcpy(out[2 * c + 1].data(), set.cameras[c].b.image.data(), out[2 * c + 1].size());
    }
    benchmark::ClobberMemory();
  }
  report_cpu_cost(state, process_cpu_seconds() - cpu0, state.iterations() * set_bytes(set));
  state.SetBytesProcessed(state.iterations() * set_bytes(set));
}
BENCHMARK(BM_MemcpySet)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

// A producer thread sends the same set (zero-copy, so it costs the producer nothing) as fast
// as back-pressure allows; the benchmark thread receives and decodes.
void stream_sets(benchmark::State& state, const char* address, int io_threads, int high_water_mark) {
  const tomorig::FrameSet& set = shared_set();
  zmq::context_t context(io_threads);
  tomorig::stream::SocketOptions out;
  out.endpoint.address = address;
  out.timeout = 10s;
  out.high_water_mark = high_water_mark;
  tomorig::stream::FrameSender sender(context, out);
  tomorig::stream::SocketOptions in = out;
  in.endpoint = {sender.endpoint(), false, false};
  tomorig::stream::FrameReceiver receiver(context, in);

  const auto total = static_cast<std::int64_t>(state.max_iterations);
  const double cpu0 = process_cpu_seconds();
  std::thread producer([&] {
    for (std::int64_t i = 0; i < total; ++i) {
      tomorig::FrameSet s = set;  // shares the pixel buffers
      s.set_index = static_cast<std::uint64_t>(i);
      if (!sender.send(s)) return;
    }
  });
  for (auto _ : state) {
    auto got = receiver.receive();
    if (!got) {
      state.SkipWithError("receive timed out");
      break;
    }
    benchmark::DoNotOptimize(got->cameras[kCameras - 1].b.image.data());
  }
  producer.join();
  report_cpu_cost(state, process_cpu_seconds() - cpu0, state.iterations() * set_bytes(set));
  state.SetBytesProcessed(state.iterations() * set_bytes(set));
  state.counters["sets_missing"] = static_cast<double>(receiver.stats().sets_missing);
  state.counters["blocked_sends"] = static_cast<double>(sender.stats().blocked_sends);
}

// Loopback TCP, as between `tomorig acquire` and `tomorig record`: the kernel copies every
// byte twice. Arguments: ZeroMQ I/O threads, high-water mark in sets.
void BM_StreamTcp(benchmark::State& state) {
  stream_sets(state, "tcp://127.0.0.1:*", static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
}
BENCHMARK(BM_StreamTcp)
    ->ArgNames({"io_threads", "hwm"})
    ->Args({1, 4})
    ->Args({2, 4})
    ->Args({1, 16})
    ->Iterations(48)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// inproc, as inside `tomorig run`: the receiver gets the sender's buffers, no byte moves; this
// measures the per-set cost of encoding, queueing and decoding.
void BM_StreamInproc(benchmark::State& state) { stream_sets(state, "inproc://bench", 1, 4); }
BENCHMARK(BM_StreamInproc)->Iterations(480)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

