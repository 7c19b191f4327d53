#include "tomorig/storage/image_file.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tomorig/core/error.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace {

void require_file(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw bad_input(fmt::format("image file '{}' does not exist", file.string()));
  if (fs::is_directory(file, ec)) throw bad_input(fmt::format("'{}' is a folder, not an image file", file.string()));
}

std::string describe(const fs::path& file, int page) {
  return page > 0 ? fmt::format("'{}' (page {})", file.string(), page + 1) : fmt::format("'{}'", file.string());
}

// Wraps the decoded matrix without copying: the Image's lease keeps the cv::Mat alive.
Image to_image(cv::Mat mat, const fs::path& file, int page) {
  SampleType type;
  if (mat.type() == CV_8UC1) {
    type = SampleType::u8;
  } else if (mat.type() == CV_16UC1) {
    type = SampleType::u16;
  } else {
    throw bad_input(fmt::format("{} has {} channel(s) of {}-bit {} samples; tomorig imports single-channel 8- or "
                                "16-bit unsigned images",
                                describe(file, page), mat.channels(), 8 * mat.elemSize1(),
                                mat.depth() == CV_32F || mat.depth() == CV_64F ? "floating-point" : "integer"));
  }
  auto holder = std::make_shared<cv::Mat>(std::move(mat));
  return Image::view(holder->data, holder->cols, holder->rows, type, holder->step[0], holder);
}

}  // namespace

int image_page_count(const fs::path& file) {
  require_file(file);
  std::size_t pages = 0;
  try {
    pages = cv::imcount(file.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw bad_input(fmt::format("cannot read image file '{}': {}", file.string(), e.what()));
  }
  if (pages == 0)
    throw bad_input(fmt::format("cannot read '{}' as an image (unknown format or damaged file)", file.string()));
  return static_cast<int>(pages);
}

Image read_image(const fs::path& file, int page) {
  require_file(file);
  try {
    if (page == 0) {
      cv::Mat mat = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
      if (mat.empty())
        throw bad_input(fmt::format("cannot read '{}' as an image (unknown format or damaged file)", file.string()));
      return to_image(std::move(mat), file, 0);
    }
    std::vector<cv::Mat> mats;
    if (!cv::imreadmulti(file.string(), mats, page, 1, cv::IMREAD_UNCHANGED) || mats.empty() || mats[0].empty())
      throw bad_input(fmt::format("cannot read page {} of '{}'", page + 1, file.string()));
    return to_image(std::move(mats[0]), file, page);
  } catch (const cv::Exception& e) {
    throw bad_input(fmt::format("cannot read image file '{}': {}", file.string(), e.what()));
  }
}

}  // namespace tomorig::storage

namespace tomorig::storage {

namespace {

std::vector<uchar> png_bytes(const Image& image, const std::string& what) {
  if (image.empty()) throw bad_input(fmt::format("cannot write {}: the image is empty", what));
  if (image.type() == SampleType::f32)
    throw bad_input(fmt::format("cannot write {}: PNG holds 8- or 16-bit samples, not float; scale the image first",
                                what));
  const int cv_type = image.type() == SampleType::u8 ? CV_8UC1 : CV_16UC1;
  // A header over the pixels, no copy; imencode only reads them.
  const cv::Mat mat(image.height(), image.width(), cv_type, const_cast<std::byte*>(image.data()), image.stride_bytes());
  std::vector<uchar> encoded;
  try {
    if (!cv::imencode(".png", mat, encoded)) throw bad_input(fmt::format("OpenCV cannot encode {}", what));
  } catch (const cv::Exception& e) {
    throw bad_input(fmt::format("OpenCV cannot encode {}: {}", what, e.what()));
  }
  return encoded;
}

}  // namespace

std::string encode_png(const Image& image) {
  const std::vector<uchar> bytes = png_bytes(image, "a PNG");
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

Image decode_png(std::string_view bytes, std::string_view what) {
  cv::Mat mat;
  try {
    const cv::Mat raw(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data()));
    if (!bytes.empty()) mat = cv::imdecode(raw, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw bad_input(fmt::format("{} is not a readable image: {}", what, e.what()));
  }
  if (mat.empty() || mat.channels() != 1 || (mat.depth() != CV_8U && mat.depth() != CV_16U))
    throw bad_input(fmt::format("{} is not a single-channel 8- or 16-bit PNG", what));
  Image out = Image::allocate(mat.cols, mat.rows, mat.depth() == CV_8U ? SampleType::u8 : SampleType::u16);
  for (int y = 0; y < mat.rows; ++y)
    std::memcpy(out.data() + static_cast<std::size_t>(y) * out.stride_bytes(), mat.ptr(y), out.row_bytes());
  return out;
}

void write_png(const fs::path& file, const Image& image) {
  const std::vector<uchar> encoded = png_bytes(image, "'" + file.string() + "'");
  const fs::path partial = fs::path(file).concat(".partial");
  {
    std::FILE* out = std::fopen(partial.c_str(), "wb");
    if (out == nullptr)
      throw bad_input(fmt::format("cannot write '{}': is folder '{}' there and writable?", file.string(),
                                  file.parent_path().string()));
    const bool ok = std::fwrite(encoded.data(), 1, encoded.size(), out) == encoded.size();
    if (std::fclose(out) != 0 || !ok) {
      std::error_code ignored;
      fs::remove(partial, ignored);
      throw runtime_error(fmt::format("writing '{}' failed (is the disk full?)", file.string()));
    }
  }
  std::error_code ec;
  fs::rename(partial, file, ec);
  if (ec) throw runtime_error(fmt::format("cannot rename '{}' to '{}': {}", partial.string(), file.string(), ec.message()));
}

}  // namespace tomorig::storage
