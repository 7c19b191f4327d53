// The preprocessing steps on float images. Each step works in place on current_ or writes a
// filtered copy into scratch_ and swaps; both buffers live as long as the chain, so frames
// after the first of a size allocate nothing of ours (OpenCV's filters keep small internal
// scratch of their own).
#include "tomorig/processing/preprocess/image_chain.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/core.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "tomorig/core/error.h"

namespace tomorig::preprocess {
namespace {

cv::Mat as_mat(Image& image) {
  return cv::Mat(image.height(), image.width(), CV_32F, image.data(), image.stride_bytes());
}

// Copies any sample type into a float image of the same size, (re)allocating `out` only when
// its size or type differs.
void convert_to_float(const Image& in, Image& out) {
  if (out.empty() || out.width() != in.width() || out.height() != in.height() || out.type() != SampleType::f32)
    out = Image::allocate(in.width(), in.height(), SampleType::f32);
  for (int y = 0; y < in.height(); ++y) {
    float* dst = out.row<float>(y);
    switch (in.type()) {
      case SampleType::u8: {
        const auto* src = in.row<std::uint8_t>(y);
        for (int x = 0; x < in.width(); ++x) dst[x] = src[x];
        break;
      }
      case SampleType::u16: {
        const auto* src = in.row<std::uint16_t>(y);
        for (int x = 0; x < in.width(); ++x) dst[x] = src[x];
        break;
      }
      case SampleType::f32: {
        const float* src = in.row<float>(y);
        std::copy(src, src + in.width(), dst);
        break;
      }
    }
  }
}

// fn(value, other) -> new value, applied pixelwise with a second image of the same size.
template <typename Fn>
void combine(Image& image, const Image& other, Fn&& fn) {
  for (int y = 0; y < image.height(); ++y) {
    float* v = image.row<float>(y);
    const float* o = other.row<float>(y);
    for (int x = 0; x < image.width(); ++x) v[x] = fn(v[x], o[x]);
  }
}

template <typename Fn>
void transform(Image& image, Fn&& fn) {
  for (int y = 0; y < image.height(); ++y) {
    float* v = image.row<float>(y);
    for (int x = 0; x < image.width(); ++x) v[x] = fn(v[x]);
  }
}

double mean_of(Image& image) { return cv::mean(as_mat(image))[0]; }

}  // namespace

ImageChain::ImageChain(ChainSpec spec) : spec_(std::move(spec)) {
  for (std::size_t i = 0; i < spec_.steps.size(); ++i) validate(spec_.steps[i], i);
  references_.resize(spec_.steps.size());
  reference_means_.resize(spec_.steps.size(), 0.0);
  sequence_.resize(spec_.steps.size());
}

void ImageChain::set_reference_image(std::size_t step, const Image& image) {
  if (step >= spec_.steps.size() || !needs_reference_image(spec_.steps[step]))
    throw bad_input(fmt::format("preprocess step {} takes no reference image (only subtract_dark with a file and "
                                "flat_field do)", step));
  if (image.empty()) throw bad_input(fmt::format("preprocess step {} ({}): the reference image is empty", step,
                                                 to_string(spec_.steps[step].kind)));
  convert_to_float(image, references_[step]);
  reference_means_[step] = mean_of(references_[step]);
  if (spec_.steps[step].kind == StepKind::flat_field && !(reference_means_[step] > 0))
    throw bad_input(fmt::format("preprocess step {} (flat_field): the bright-field image '{}' is dark (mean {}); "
                                "give frames of a uniformly lit target", step, spec_.steps[step].file,
                                reference_means_[step]));
}

void ImageChain::set_sequence_image(std::size_t step, Exposure e, const Image& image) {
  if (step >= spec_.steps.size() || !needs_sequence_image(spec_.steps[step]))
    throw bad_input(fmt::format("preprocess step {} takes no sequence image (only subtract_minimum and normalize by "
                                "average_image do)", step));
  if (image.empty()) throw bad_input(fmt::format("preprocess step {} ({}): the sequence image is empty", step,
                                                 to_string(spec_.steps[step].kind)));
  convert_to_float(image, sequence_[step][static_cast<int>(e)]);
}

const Image& ImageChain::run(const Image& in, Exposure e, std::size_t end) {
  if (in.empty()) throw bad_input("preprocess: the input frame is empty (a missing frame cannot be preprocessed)");
  convert_to_float(in, current_);
  const std::size_t last = std::min(end, spec_.steps.size());
  for (std::size_t i = 0; i < last; ++i) apply(i, e);
  return current_;
}

const Image& ImageChain::required(const Image& image, std::size_t index, const char* what) const {
  const Step& step = spec_.steps[index];
  if (image.empty())
    throw bad_input(fmt::format("preprocess step {} ({}): no {} was given for this camera", index, to_string(step.kind),
                                what));
  if (image.width() != current_.width() || image.height() != current_.height())
    throw bad_input(fmt::format("preprocess step {} ({}): the {} is {} x {} but the frame is {} x {}", index,
                                to_string(step.kind), what, image.width(), image.height(), current_.width(),
                                current_.height()));
  return image;
}

void ImageChain::local_bright_field(int tile) {
  if (scratch_.empty() || scratch_.width() != current_.width() || scratch_.height() != current_.height())
    scratch_ = Image::allocate(current_.width(), current_.height(), SampleType::f32);
  const int w = current_.width(), h = current_.height();
  const int tiles_x = std::max(1, (w + tile / 2) / tile), tiles_y = std::max(1, (h + tile / 2) / tile);
  // The median of each tile (tiles split the frame evenly, so the last ones are not slivers).
  tile_levels_.resize(static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y));
  for (int ty = 0; ty < tiles_y; ++ty)
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int x0 = tx * w / tiles_x, x1 = (tx + 1) * w / tiles_x, y0 = ty * h / tiles_y, y1 = (ty + 1) * h / tiles_y;
      sort_buffer_.clear();
      for (int y = y0; y < y1; ++y) {
        const float* row = current_.row<float>(y);
        sort_buffer_.insert(sort_buffer_.end(), row + x0, row + x1);
      }
      const auto mid = sort_buffer_.begin() + static_cast<std::ptrdiff_t>(sort_buffer_.size() / 2);
      std::nth_element(sort_buffer_.begin(), mid, sort_buffer_.end());
      tile_levels_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x) + static_cast<std::size_t>(tx)] = *mid;
    }
  // Bilinear between the tile centres and extrapolated linearly into the outer half-tiles
  // (vignetting keeps falling there; holding the last level would leave a rim of background).
  const double tw = static_cast<double>(w) / tiles_x, th = static_cast<double>(h) / tiles_y;
  const auto cell = [](double u, int tiles, int& i0) {
    i0 = tiles < 2 ? 0 : std::clamp(static_cast<int>(std::floor(u)), 0, tiles - 2);
    return tiles < 2 ? 0.0 : u - i0;
  };
  const auto level = [&](int tx, int ty) {
    return static_cast<double>(tile_levels_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x) +
                                            static_cast<std::size_t>(tx)]);
  };
  for (int y = 0; y < h; ++y) {
    int j0 = 0;
    const double fy = cell((y + 0.5) / th - 0.5, tiles_y, j0);
    const int j1 = std::min(j0 + 1, tiles_y - 1);
    float* out = scratch_.row<float>(y);
    for (int x = 0; x < w; ++x) {
      int i0 = 0;
      const double fx = cell((x + 0.5) / tw - 0.5, tiles_x, i0);
      const int i1 = std::min(i0 + 1, tiles_x - 1);
      const double top = level(i0, j0) + fx * (level(i1, j0) - level(i0, j0));
      const double bottom = level(i0, j1) + fx * (level(i1, j1) - level(i0, j1));
      // Never below a tenth of the nearest tile's level: an extrapolation must not divide by ~0.
      const double nearest = level(fx < 0.5 ? i0 : i1, fy < 0.5 ? j0 : j1);
      out[x] = static_cast<float>(std::max(top + fy * (bottom - top), 0.1 * nearest));
    }
  }
}

void ImageChain::apply(std::size_t index, Exposure e) {
  const Step& step = spec_.steps[index];
  const auto ensure_scratch = [&] {
    if (scratch_.empty() || scratch_.width() != current_.width() || scratch_.height() != current_.height())
      scratch_ = Image::allocate(current_.width(), current_.height(), SampleType::f32);
  };
  switch (step.kind) {
    case StepKind::subtract_dark: {
      if (step.file.empty()) {
        const auto level = static_cast<float>(step.level);
        transform(current_, [level](float v) { return std::max(v - level, 0.0f); });
      } else {
        combine(current_, required(references_[index], index, "dark image"),
                [](float v, float d) { return std::max(v - d, 0.0f); });
      }
      break;
    }
    case StepKind::subtract_minimum:
      combine(current_, required(sequence_[index][static_cast<int>(e)], index, "sequence minimum image"),
              [](float v, float m) { return std::max(v - m, 0.0f); });
      break;
    case StepKind::subtract_local_minimum: {
      ensure_scratch();
      cv::Mat out = as_mat(scratch_);
      // Erosion is the sliding minimum; the default border ignores pixels outside the image.
      cv::erode(as_mat(current_), out, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(step.size, step.size)));
      combine(current_, scratch_, [](float v, float m) { return std::max(v - m, 0.0f); });
      break;
    }
    case StepKind::median: {
      ensure_scratch();
      cv::Mat out = as_mat(scratch_);
      cv::medianBlur(as_mat(current_), out, step.size);
      std::swap(current_, scratch_);
      break;
    }
    case StepKind::lowpass:
    case StepKind::highpass: {
      ensure_scratch();
      cv::Mat out = as_mat(scratch_);
      cv::GaussianBlur(as_mat(current_), out, cv::Size(0, 0), step.sigma, step.sigma, cv::BORDER_REFLECT);
      if (step.kind == StepKind::lowpass)
        std::swap(current_, scratch_);
      else
        combine(current_, scratch_, [](float v, float low) { return std::max(v - low, 0.0f); });
      break;
    }
    case StepKind::normalize: {
      const auto target = static_cast<float>(step.target);
      if (step.by == NormalizeBy::mean) {
        const double mean = mean_of(current_);
        const float scale = mean > 0 ? static_cast<float>(step.target / mean) : 0.0f;
        transform(current_, [scale](float v) { return v * scale; });
      } else if (step.by == NormalizeBy::local) {
        local_bright_field(step.size);
        combine(current_, scratch_, [target](float v, float bright) { return bright > 0 ? v / bright * target : 0.0f; });
      } else {
        combine(current_, required(sequence_[index][static_cast<int>(e)], index, "sequence average image"),
                [target](float v, float avg) { return avg > 0 ? v / avg * target : 0.0f; });
      }
      break;
    }
    case StepKind::flat_field: {
      const auto mean = static_cast<float>(reference_means_[index]);
      combine(current_, required(references_[index], index, "bright-field image"),
              [mean](float v, float bright) { return bright > 0 ? v / bright * mean : 0.0f; });
      break;
    }
    case StepKind::invert: {
      const auto max = static_cast<float>(step.max);
      transform(current_, [max](float v) { return std::max(max - v, 0.0f); });
      break;
    }
    case StepKind::clip: {
      float threshold = static_cast<float>(step.level);
      if (step.use_sigmas) {
        // Robust background statistics: the median is the background level as long as
        // particles cover under half the pixels; 1.4826 MAD is sigma for Gaussian noise and
        // ignores the particles' bright tail.
        const std::size_t n = static_cast<std::size_t>(current_.width()) * static_cast<std::size_t>(current_.height());
        sort_buffer_.resize(n);
        for (int y = 0; y < current_.height(); ++y)
          std::copy_n(current_.row<float>(y), current_.width(),
                      sort_buffer_.begin() + static_cast<std::ptrdiff_t>(y) * current_.width());
        const auto mid = sort_buffer_.begin() + static_cast<std::ptrdiff_t>(n / 2);
        std::nth_element(sort_buffer_.begin(), mid, sort_buffer_.end());
        const float median = *mid;
        for (float& v : sort_buffer_) v = std::abs(v - median);
        std::nth_element(sort_buffer_.begin(), mid, sort_buffer_.end());
        const float sigma = 1.4826f * *mid;
        threshold = median + static_cast<float>(step.sigmas) * sigma;
      }
      const bool subtract = step.subtract;
      transform(current_, [threshold, subtract](float v) {
        if (v < threshold) return 0.0f;
        return subtract ? v - threshold : v;
      });
      break;
    }
  }
}

void to_uint16(const Image& in, Image& out) {
  if (out.empty() || out.width() != in.width() || out.height() != in.height() || out.type() != SampleType::u16)
    out = Image::allocate(in.width(), in.height(), SampleType::u16);
  for (int y = 0; y < in.height(); ++y) {
    const float* src = in.row<float>(y);
    auto* dst = out.row<std::uint16_t>(y);
    for (int x = 0; x < in.width(); ++x) {
      const float v = src[x];
      // NaN compares false both ways and ends at 0.
      const float clipped = v > 65535.0f ? 65535.0f : (v > 0.0f ? v : 0.0f);
      dst[x] = static_cast<std::uint16_t>(std::lround(clipped));
    }
  }
}

}  // namespace tomorig::preprocess
