#include "set_result_codec.h"

#include <cstdint>
#include <cstring>
#include <type_traits>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::pipeline {
namespace {

constexpr std::uint32_t kMagic = 0x746f6d72;  // "tomr"

// Fixed-size part, followed by displacement, status, peak (count() each) and the report text.
struct Header {
  std::uint32_t magic = kMagic;
  std::int32_t nx = 0, ny = 0, nz = 0;
  std::uint64_t set_index = 0;
  std::int64_t dt_ns = 0;
  double seconds = 0.0;
  double origin[3] = {0, 0, 0};
  double spacing[3] = {0, 0, 0};
  std::uint64_t vectors = 0;
  double valid_fraction = 0.0;
  std::uint64_t report_bytes = 0;
};
static_assert(std::is_trivially_copyable_v<Header>);
static_assert(std::is_trivially_copyable_v<Vec3f> && sizeof(Vec3f) == 12);

// Copies n bytes to `at` and returns the position after them (a buffer sized in advance).
char* put(char* at, const void* data, std::size_t n) {
  if (n > 0) std::memcpy(at, data, n);
  return at + n;
}

}  // namespace

std::vector<char> encode_finished_set(const FinishedSet& set) {
  const storage::SetResult& r = set.result;
  const VectorField& f = r.field;
  Header h;
  h.nx = f.nx;
  h.ny = f.ny;
  h.nz = f.nz;
  h.set_index = r.set_index;
  h.dt_ns = r.dt_ns;
  h.seconds = r.seconds;
  h.origin[0] = f.origin.x, h.origin[1] = f.origin.y, h.origin[2] = f.origin.z;
  h.spacing[0] = f.spacing.x, h.spacing[1] = f.spacing.y, h.spacing[2] = f.spacing.z;
  h.vectors = set.vectors;
  h.valid_fraction = set.valid_fraction;
  h.report_bytes = r.report_json.size();
  const std::size_t n = f.count();
  std::vector<char> out(sizeof h + n * (sizeof(Vec3f) + sizeof(VectorStatus) + sizeof(float)) + r.report_json.size());
  char* at = put(out.data(), &h, sizeof h);
  at = put(at, f.displacement.data(), n * sizeof(Vec3f));
  at = put(at, f.status.data(), n * sizeof(VectorStatus));
  at = put(at, f.peak.data(), n * sizeof(float));
  put(at, r.report_json.data(), r.report_json.size());
  return out;
}

FinishedSet decode_finished_set(const std::vector<char>& bytes) {
  Header h;
  const auto broken = [&](const char* why) {
    return runtime_error(fmt::format("a finished set from a worker rank ({} bytes) is damaged: {}", bytes.size(), why));
  };
  if (bytes.size() < sizeof h) throw broken("shorter than its header");
  std::memcpy(&h, bytes.data(), sizeof h);
  if (h.magic != kMagic) throw broken("wrong magic number (another program on that rank?)");
  if (h.nx < 0 || h.ny < 0 || h.nz < 0) throw broken("negative field size");
  const std::size_t n = static_cast<std::size_t>(h.nx) * h.ny * h.nz;
  const std::size_t expected = sizeof h + n * (sizeof(Vec3f) + sizeof(VectorStatus) + sizeof(float)) + h.report_bytes;
  if (bytes.size() != expected) throw broken("its length does not match its field size and report");
  FinishedSet set;
  storage::SetResult& r = set.result;
  r.set_index = h.set_index;
  r.dt_ns = h.dt_ns;
  r.seconds = h.seconds;
  VectorField& f = r.field;
  f = VectorField(h.nx, h.ny, h.nz);
  f.origin = {h.origin[0], h.origin[1], h.origin[2]};
  f.spacing = {h.spacing[0], h.spacing[1], h.spacing[2]};
  const char* p = bytes.data() + sizeof h;
  std::memcpy(f.displacement.data(), p, n * sizeof(Vec3f));
  p += n * sizeof(Vec3f);
  std::memcpy(f.status.data(), p, n * sizeof(VectorStatus));
  p += n * sizeof(VectorStatus);
  std::memcpy(f.peak.data(), p, n * sizeof(float));
  p += n * sizeof(float);
  r.report_json.assign(p, h.report_bytes);
  set.vectors = h.vectors;
  set.valid_fraction = h.valid_fraction;
  return set;
}

}  // namespace tomorig::pipeline
