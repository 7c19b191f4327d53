// The direct-write driver's helper threads (storage/src/piece_writers.h): every piece of every
// write is written exactly once, by any mix of helpers and caller, and the first failure in
// piece order is what the write reports.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <thread>

#include "piece_writers.h"

namespace tomorig::storage {
namespace {

TEST(PieceWriters, EveryPieceOfEveryWriteIsWrittenOnceOnSeveralThreads) {
  PieceWriters writers(3);
  for (std::size_t pieces = 1; pieces <= 6; ++pieces) {  // 5 and 6: more pieces than helpers + 1
    for (int write = 0; write < 200; ++write) {
      std::array<std::atomic<int>, 6> times{};
      std::array<std::thread::id, 6> by{};
      const int result = writers.run(pieces, [&](std::size_t k) {
        times[k].fetch_add(1);
        by[k] = std::this_thread::get_id();
        return 0;
      });
      ASSERT_EQ(result, 0);
      for (std::size_t k = 0; k < times.size(); ++k) ASSERT_EQ(times[k].load(), k < pieces ? 1 : 0) << pieces << " pieces, piece " << k;
      EXPECT_EQ(by[pieces - 1], std::this_thread::get_id()) << "the caller writes the last piece";
      if (pieces > 1) EXPECT_NE(by[0], std::this_thread::get_id()) << "the first piece goes to a helper";
    }
  }
}

TEST(PieceWriters, TheFirstFailingPieceInOrderIsReported) {
  PieceWriters writers(3);
  EXPECT_EQ(writers.run(4, [](std::size_t k) { return k == 2 ? 28 : (k == 3 ? 5 : 0); }), 28);
  EXPECT_EQ(writers.run(4, [](std::size_t k) { return k == 3 ? 5 : 0; }), 5);
  EXPECT_EQ(writers.run(4, [](std::size_t) { return 0; }), 0);  // nothing carried over
}

TEST(PieceWriters, WithoutHelpersTheCallerWritesEveryPiece) {
  PieceWriters writers(0);
  int written = 0;
  EXPECT_EQ(writers.run(4, [&](std::size_t) {
    ++written;  // no other thread: no race
    return 0;
  }), 0);
  EXPECT_EQ(written, 4);
}

}  // namespace
}  // namespace tomorig::storage
