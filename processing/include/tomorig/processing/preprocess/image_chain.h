#pragma once
// Runs a preprocessing chain on the frames of one camera. Work is done on float images in
// buffers owned by the chain: after the first frame of a size, a frame allocates nothing.
//
// Steps that need a sequence statistic (subtract_minimum, normalize by average_image) get it
// from set_sequence_image(); the caller computes it in an earlier pass with run(in, e, step)
// (the chain up to that step) fed into a MinimumImage or MeanImage (sequence_image.h).
#include <array>
#include <cstddef>
#include <limits>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/core/image.h"
#include "tomorig/processing/preprocess/chain_spec.h"

namespace tomorig::preprocess {

class ImageChain {
 public:
  static constexpr std::size_t all_steps = std::numeric_limits<std::size_t>::max();

  explicit ImageChain(ChainSpec spec);  // validates every step

  const ChainSpec& spec() const { return spec_; }

  // The dark or bright-field image of step `step` (any sample type; copied as float).
  void set_reference_image(std::size_t step, const Image& image);
  // The sequence minimum or average for step `step` and exposure `e` (copied as float).
  void set_sequence_image(std::size_t step, Exposure e, const Image& image);

  // Runs steps [0, end) on `in` (u8, u16 or f32). The result is a float image owned by the
  // chain, valid until the next call. bad_input if a step lacks its reference or sequence
  // image or if an image size does not match.
  const Image& run(const Image& in, Exposure e, std::size_t end = all_steps);

 private:
  void apply(std::size_t index, Exposure e);
  // normalize by local: the frame's bright field (tile medians, interpolated) into scratch_.
  void local_bright_field(int tile);
  const Image& required(const Image& image, std::size_t index, const char* what) const;

  ChainSpec spec_;
  std::vector<Image> references_;                   // per step
  std::vector<double> reference_means_;             // flat_field: mean of the bright field
  std::vector<std::array<Image, 2>> sequence_;      // per step, per exposure
  Image current_;                                   // the working image
  Image scratch_;                                   // second buffer for filters
  std::vector<float> sort_buffer_;                  // clip: background statistics
  std::vector<float> tile_levels_;                  // normalize by local: the tiles' medians
};

// Float to uint16: values rounded to nearest and clipped to [0, 65535]; `out` is reused when
// its size fits, otherwise allocated.
void to_uint16(const Image& in, Image& out);

}  // namespace tomorig::preprocess
