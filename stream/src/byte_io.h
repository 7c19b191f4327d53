#pragma once
// Little-endian field writer and bounds-checked reader for the wire header. Bytes are assembled
// one by one, so the layout is the same whatever the host's endianness or alignment.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/error.h"

namespace tomorig::stream::detail {

class ByteWriter {
 public:
  explicit ByteWriter(std::vector<std::byte>& out) : out_(out) {}

  void u8(std::uint8_t v) { out_.push_back(static_cast<std::byte>(v)); }
  void u16(std::uint16_t v) { put(v, 2); }
  void u32(std::uint32_t v) { put(v, 4); }
  void u64(std::uint64_t v) { put(v, 8); }
  void i64(std::int64_t v) { put(static_cast<std::uint64_t>(v), 8); }
  void f64(double v) { put(std::bit_cast<std::uint64_t>(v), 8); }  // IEEE 754 binary64
  void bytes(const void* data, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = out_.size();
    out_.resize(at + n);
    std::memcpy(out_.data() + at, data, n);
  }

 private:
  void put(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<std::byte>((v >> (8 * i)) & 0xffu));
  }
  std::vector<std::byte>& out_;
};

// Every read checks that the field lies inside the buffer; a short buffer throws bad_input
// naming the message and the field, so a truncated or lying header can never be read past its
// end. `what` names the message in errors ("wire header", "session-start message").
class ByteReader {
 public:
  explicit ByteReader(std::span<const std::byte> data, const char* what = "wire header") : data_(data), what_(what) {}

  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }

  std::uint8_t u8(const char* field) { return static_cast<std::uint8_t>(get(1, field)); }
  std::uint16_t u16(const char* field) { return static_cast<std::uint16_t>(get(2, field)); }
  std::uint32_t u32(const char* field) { return static_cast<std::uint32_t>(get(4, field)); }
  std::uint64_t u64(const char* field) { return get(8, field); }
  std::int64_t i64(const char* field) { return static_cast<std::int64_t>(get(8, field)); }
  double f64(const char* field) { return std::bit_cast<double>(get(8, field)); }
  std::string string(std::size_t n, const char* field) {
    require(n, field);
    std::string s(reinterpret_cast<const char*>(data_.data() + pos_), n);
    pos_ += n;
    return s;
  }

 private:
  void require(std::size_t n, const char* field) const {
    if (n > remaining())
      throw bad_input("truncated " + std::string(what_) + ": field '" + std::string(field) + "' needs " +
                      std::to_string(n) + " bytes at offset " + std::to_string(pos_) + " but the message has only " +
                      std::to_string(data_.size()) + " bytes");
  }
  std::uint64_t get(int n, const char* field) {
    require(static_cast<std::size_t>(n), field);
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(data_[pos_ + i]) << (8 * i);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }

  std::span<const std::byte> data_;
  const char* what_;
  std::size_t pos_ = 0;
};

}  // namespace tomorig::stream::detail
