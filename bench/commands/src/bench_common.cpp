#include "bench_common.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/core/version.h"

namespace tomorig::bench {
namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      return colon == std::string::npos ? line : line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

double memory_gb() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) / (1u << 30) : 0.0;
}

}  // namespace

nlohmann::json machine_json() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return {{"cpu", cpu_model()},
          {"cores", std::thread::hardware_concurrency()},
          {"memory_gb", std::round(memory_gb() * 10) / 10},
          {"hostname", host},
          {"software_version", std::string(software_version())}};
}

double memory_pass_seconds(std::size_t floats) {
  // The buffer is fresh, as a new volume would be, so first-touch page faults are included.
  const auto start = std::chrono::steady_clock::now();
  const auto buffer = std::make_unique_for_overwrite<float[]>(floats);
  for (std::size_t i = 0; i < floats; ++i) buffer[i] = static_cast<float>(i & 1023);
  double sum = 0.0;
  for (std::size_t i = 0; i < floats; ++i) sum += buffer[i];
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  volatile double keep = sum;  // the reads must happen
  (void)keep;
  return seconds;
}

nlohmann::json json_number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

void write_json(const nlohmann::json& value, const std::string& path) {
  const std::string text = value.dump(2) + "\n";
  if (path.empty() || path == "-") {
    fmt::print("{}", text);
    return;
  }
  const std::filesystem::path partial = path + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (!out) throw bad_input(fmt::format("cannot write '{}': is the folder there and writable?", path));
    out << text;
    if (!out.flush()) throw runtime_error(fmt::format("writing '{}' failed (is the disk full?)", partial.string()));
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) throw runtime_error(fmt::format("cannot rename '{}' to '{}': {}", partial.string(), path, ec.message()));
  fmt::print(stderr, "wrote {}\n", path);
}

FrameSet synthetic_particle_set(int cameras, int side, std::uint64_t seed) {
  FrameSet set;
  set.dt_ns = 100'000;
  std::uint64_t state = seed * 0x9E3779B97F4A7C15ull + 1;
  auto next = [&state] {  // xorshift64: fast and good enough for test pixels
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
  };
  for (int c = 0; c < cameras; ++c) {
    CameraFrames cam;
    cam.camera_id = "cam" + std::to_string(c);
    for (Frame* f : {&cam.a, &cam.b}) {
      f->image = Image::allocate(side, side, SampleType::u16);
      for (int y = 0; y < side; ++y) {
        auto* row = f->image.row<std::uint16_t>(y);
        for (int x = 0; x < side; ++x) row[x] = static_cast<std::uint16_t>(90 + (next() & 15));
      }
      // 0.05 particle images per pixel, 3 x 3 px each.
      const std::size_t spots = static_cast<std::size_t>(0.05 * side * side);
      for (std::size_t n = 0; n < spots; ++n) {
        const int x0 = 1 + static_cast<int>(next() % static_cast<std::uint64_t>(side - 2));
        const int y0 = 1 + static_cast<int>(next() % static_cast<std::uint64_t>(side - 2));
        const int peak = 400 + static_cast<int>(next() % 3000);
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            auto& v = f->image.at<std::uint16_t>(x0 + dx, y0 + dy);
            v = static_cast<std::uint16_t>(std::min(65535, v + peak / (1 + 2 * (dx * dx + dy * dy))));
          }
      }
    }
    set.cameras.push_back(std::move(cam));
  }
  return set;
}

std::uint64_t set_bytes(const FrameSet& set) {
  std::uint64_t n = 0;
  for (const auto& cam : set.cameras) n += cam.a.image.size_bytes() + cam.b.image.size_bytes();
  return n;
}

double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace tomorig::bench
