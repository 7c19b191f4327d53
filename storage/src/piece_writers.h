#pragma once
// Threads that live as long as one open file and write the pieces of its large direct writes
// in parallel (direct_write_driver.cpp). A recording at 4 x 2048^2, 10 Hz makes about 80 large
// writes a second; starting three threads for each (std::async) cost more than the waiting.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace tomorig::storage {

class PieceWriters {
 public:
  // `helpers` threads besides the caller's; they start with the first run().
  explicit PieceWriters(std::size_t helpers) : helpers_(helpers) {}
  ~PieceWriters();
  PieceWriters(const PieceWriters&) = delete;
  PieceWriters& operator=(const PieceWriters&) = delete;

  // Runs write_piece(k) for every k < pieces: the first ones on the helpers, the rest (at least
  // the last) on the calling thread, also those of helpers that could not be started.
  // Returns when all are done: 0, or the first non-zero result in piece order.
  int run(std::size_t pieces, const std::function<int(std::size_t)>& write_piece);

 private:
  void serve(std::size_t k);

  std::size_t helpers_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  const std::function<int(std::size_t)>* job_ = nullptr;
  std::size_t helped_ = 0;    // pieces [0, helped_) of this round go to the helpers
  std::size_t round_ = 0;     // counts run() calls: a helper takes each round once
  std::size_t remaining_ = 0; // helper pieces of this round not finished yet
  std::vector<int> results_;  // by piece; a helper writes only its own entry
  bool stopping_ = false;
};

}  // namespace tomorig::storage
