#include "bench_common.h"

#include <unistd.h>

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

namespace tomorig::app {
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

}  // namespace tomorig::app
