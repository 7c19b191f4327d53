#include "piece_writers.h"

#include <algorithm>
#include <system_error>

namespace tomorig::storage {

PieceWriters::~PieceWriters() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  start_.notify_all();
  for (auto& t : threads_) t.join();
}

void PieceWriters::serve(std::size_t k) {
  std::size_t seen_round = 0;
  std::unique_lock lock(mutex_);
  for (;;) {
    start_.wait(lock, [&] { return stopping_ || round_ != seen_round; });
    if (stopping_) return;
    seen_round = round_;
    if (k >= helped_) continue;  // this round needs fewer helpers
    const std::function<int(std::size_t)>& job = *job_;
    lock.unlock();
    const int result = job(k);
    lock.lock();
    results_[k] = result;
    if (--remaining_ == 0) done_.notify_one();
  }
}

int PieceWriters::run(std::size_t pieces, const std::function<int(std::size_t)>& write_piece) {
  if (pieces == 0) return 0;
  if (pieces > 1 && threads_.empty() && helpers_ > 0) {
    try {
      for (std::size_t k = 0; k < helpers_; ++k) threads_.emplace_back([this, k] { serve(k); });
    } catch (const std::system_error&) {
      helpers_ = threads_.size();  // go on with the threads there are (maybe none)
    }
  }
  const std::size_t helped = std::min(helpers_, pieces - 1);  // pieces [0, helped) go to helpers
  {
    std::lock_guard lock(mutex_);
    job_ = &write_piece;
    helped_ = helped;
    remaining_ = helped;
    results_.assign(pieces, 0);
    ++round_;
  }
  if (helped > 0) start_.notify_all();
  for (std::size_t k = helped; k < pieces; ++k) results_[k] = write_piece(k);
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return remaining_ == 0; });
  job_ = nullptr;
  for (const int r : results_)
    if (r != 0) return r;
  return 0;
}

}  // namespace tomorig::storage
