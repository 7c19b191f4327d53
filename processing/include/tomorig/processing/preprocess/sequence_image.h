#pragma once
// Streaming statistics over an image sequence, fed one frame at a time so a sequence never
// has to be held in memory: the pixelwise minimum and the pixelwise mean.
#include <cstdint>
#include <vector>

#include "tomorig/core/image.h"

namespace tomorig::preprocess {

class MinimumImage {
 public:
  // Any sample type; every frame must have the size of the first (bad_input otherwise).
  void add(const Image& frame);
  std::uint64_t count() const { return count_; }
  // The pixelwise minimum so far, float; bad_input if no frame was added.
  const Image& result() const;

 private:
  Image minimum_;
  std::uint64_t count_ = 0;
};

class MeanImage {
 public:
  void add(const Image& frame);
  std::uint64_t count() const { return count_; }
  // The pixelwise mean so far, float; bad_input if no frame was added.
  Image result() const;

 private:
  std::vector<double> sum_;  // double: a long sequence of 16-bit frames loses no counts
  int width_ = 0, height_ = 0;
  std::uint64_t count_ = 0;
};

}  // namespace tomorig::preprocess
