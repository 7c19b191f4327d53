// Text under a picture (OpenCV's Hershey font), for snapshots with their numbers.
#include <algorithm>
#include <cstring>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/display.h"

namespace tomorig::quicklook {

Image with_caption(const Image& image, std::span<const std::string> lines) {
  if (image.empty() || image.type() != SampleType::u8)
    throw bad_input("a caption goes under an 8-bit picture; stretch the image first");
  constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
  constexpr double kScale = 0.4;
  constexpr int kLine = 15, kMargin = 4;
  int text_width = 0;
  for (const std::string& line : lines) {
    int baseline = 0;
    text_width = std::max(text_width, cv::getTextSize(line, kFont, kScale, 1, &baseline).width);
  }
  const int width = std::max(image.width(), text_width + 2 * kMargin);
  const int height = image.height() + static_cast<int>(lines.size()) * kLine + (lines.empty() ? 0 : kMargin);
  Image out = Image::allocate(width, height, SampleType::u8);
  for (int y = 0; y < image.height(); ++y)
    std::memcpy(out.row<std::uint8_t>(y), image.row<std::uint8_t>(y), static_cast<std::size_t>(image.width()));
  cv::Mat mat(out.height(), out.width(), CV_8UC1, out.data(), out.stride_bytes());
  for (std::size_t i = 0; i < lines.size(); ++i)
    cv::putText(mat, lines[i], {kMargin, image.height() + static_cast<int>(i + 1) * kLine - 3}, kFont, kScale,
                cv::Scalar(255), 1, cv::LINE_AA);
  return out;
}

}  // namespace tomorig::quicklook
