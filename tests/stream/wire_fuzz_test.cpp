// Randomised damage to valid messages (deterministic seed): the decoder either accepts the
// message or throws tomorig::Error; it never crashes, never throws anything else, and what it
// accepts is readable end to end. Run under AddressSanitizer to also catch stray reads.
#include <gtest/gtest.h>

#include <array>
#include <random>

#include <zmq.hpp>

#include "stream_test_support.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream {
namespace {
using testing::pattern_image;
using testing::pattern_set;

FrameSet fuzz_base() {
  FrameSet set = pattern_set(11, 2, 9, 7, SampleType::u16);
  set.cameras[1].a.image = pattern_image(5, 3, SampleType::u8, 11, 1, 0);
  set.cameras[1].b = Frame{};
  return set;
}

// Reads every pixel of every frame, so a view reaching outside its part would be touched.
double touch_all_pixels(const FrameSet& set) {
  double sum = 0;
  for (const auto& cam : set.cameras)
    for (const Frame* f : {&cam.a, &cam.b})
      if (f->present())
        for (int y = 0; y < f->image.height(); ++y)
          for (int x = 0; x < f->image.width(); ++x) sum += f->image.value(x, y);
  return sum;
}

std::vector<std::byte> mutate(std::vector<std::byte> h, std::mt19937_64& rng, std::size_t frame_entries_at) {
  auto pick = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
  switch (pick(6)) {
    case 0:  // flip a few random bytes
      for (std::size_t i = 0, n = 1 + pick(4); i < n; ++i) h[pick(h.size())] ^= std::byte(1 + pick(255));
      break;
    case 1:  // truncate
      h.resize(pick(h.size()));
      break;
    case 2:  // append garbage
      for (std::size_t i = 0, n = 1 + pick(64); i < n; ++i) h.push_back(std::byte(pick(256)));
      break;
    case 3: {  // an extreme value in a field of the fixed header
      const std::size_t at = 8 + 2 * pick(20);
      const std::uint64_t v = std::array<std::uint64_t, 5>{0, 1, 0xffff, 0xffffffffull, ~0ull}[pick(5)];
      for (int i = 0; i < 8 && at + i < h.size(); ++i) h[at + i] = std::byte((v >> (8 * i)) & 0xff);
      break;
    }
    case 4: {  // an extreme value inside a frame entry (sizes, stride, byte count)
      const std::size_t at = frame_entries_at + pick(h.size() - frame_entries_at);
      const std::uint64_t v = std::array<std::uint64_t, 6>{0, 1, 2, 0x10000, 0x7fffffff, ~0ull}[pick(6)];
      for (int i = 0; i < 4 && at + i < h.size(); ++i) h[at + i] = std::byte((v >> (8 * i)) & 0xff);
      break;
    }
    default:  // a harmless change that must still decode: the trigger timestamp
      h[24 + pick(8)] ^= std::byte{0x5a};
      break;
  }
  return h;
}

TEST(WireFuzz, DamagedMessagesAreRejectedOrDecodedSafely) {
  const FrameSet base = fuzz_base();
  std::vector<std::byte> header;
  {
    const auto parts = encode_frame_set(base);
    const auto* p = static_cast<const std::byte*>(parts[0].data());
    header.assign(p, p + parts[0].size());
  }
  const std::size_t entries_at = kFixedHeaderBytes + 2 * (2 + 4);
  std::mt19937_64 rng(20261123);
  int accepted = 0, rejected = 0;
  constexpr int kCases = 4000;
  for (int i = 0; i < kCases; ++i) {
    auto parts = encode_frame_set(base);
    const auto damaged = mutate(header, rng, entries_at);
    parts[0] = zmq::message_t(damaged.data(), damaged.size());
    switch (rng() % 8) {  // sometimes also damage the part list
      case 0: parts.pop_back(); break;
      case 1: parts.emplace_back(rng() % 100); break;
      case 2: parts[1 + rng() % 4] = zmq::message_t(rng() % 200); break;
      default: break;
    }
    try {
      const FrameSet set = decode_frame_set(std::move(parts));
      EXPECT_GE(touch_all_pixels(set), 0.0);
      ++accepted;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      EXPECT_GT(std::string(e.what()).size(), 10u);
      ++rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << i << " threw a non-tomorig exception: " << e.what();
    }
  }
  EXPECT_EQ(accepted + rejected, kCases);
  EXPECT_GT(accepted, 0) << "harmless mutations must still decode";
  EXPECT_GT(rejected, kCases / 2);
}

}  // namespace
}  // namespace tomorig::stream
