#pragma once
// Seeds for every random draw of the simulator. One user seed is recorded with the output;
// every independent stream (particles of set k, noise of camera c / exposure e / row r) gets
// its own seed derived from it, so any set can be re-rendered on its own and the result does
// not depend on the order or the thread that renders it.
#include <cstdint>
#include <initializer_list>

namespace tomorig::sim {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective, well-mixed 64-bit hash.
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A seed for the stream named by `path` under `base`, e.g. derive_seed(seed, {kNoise, set, cam}).
constexpr std::uint64_t derive_seed(std::uint64_t base, std::initializer_list<std::uint64_t> path) {
  std::uint64_t h = splitmix64(base);
  for (std::uint64_t p : path) h = splitmix64(h ^ splitmix64(p));
  return h;
}

// A double uniform in [0, 1) from the top 53 bits of a 64-bit engine. Written out (rather than
// std::uniform_real_distribution, whose algorithm the standard leaves open) so that particle
// fields are the same with every standard library.
template <typename Engine>
double unit_double(Engine& engine) {
  return static_cast<double>(engine() >> 11) * 0x1.0p-53;
}

// Stream tags for derive_seed.
inline constexpr std::uint64_t kParticleStream = 0x7061727469636c65ULL;  // "particle"
inline constexpr std::uint64_t kNoiseStream = 0x6e6f697365ULL;           // "noise"

}  // namespace tomorig::sim
