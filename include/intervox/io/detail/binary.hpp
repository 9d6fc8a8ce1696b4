#pragma once
/// \file
/// Internal: little-endian encoding, CRC-32 and a bounds-checked reader over a byte buffer.
/// Not part of the public API.

#include <intervox/core/error.hpp>

#include <array>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

namespace intervox::detail {

/// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), as zlib's crc32().
inline std::uint32_t crc32(std::string_view bytes, std::uint32_t crc = 0) noexcept {
  static constexpr auto kTable = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (const char ch : bytes) crc = kTable[(crc ^ static_cast<std::uint8_t>(ch)) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

/// Appends little-endian encodings to a byte string.
class ByteWriter {
 public:
  void u8(std::uint8_t v) { out_.push_back(static_cast<char>(v)); }
  void u16(std::uint16_t v) { uint(v, 2); }
  void u32(std::uint32_t v) { uint(v, 4); }
  void u64(std::uint64_t v) { uint(v, 8); }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void bytes(std::string_view s) { out_.append(s); }
  /// An unsigned LEB128 varint: 7 bits per byte, low bits first, high bit set on all but the last.
  void varint(std::uint64_t v) {
    while (v >= 0x80u) {
      out_.push_back(static_cast<char>((v & 0x7Fu) | 0x80u));
      v >>= 7;
    }
    out_.push_back(static_cast<char>(v));
  }
  /// A signed value as a zigzag varint (0, -1, 1, -2, ... -> 0, 1, 2, 3, ...).
  void svarint(std::int64_t v) { varint((static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63)); }
  /// A string prefixed by its 16-bit length.
  void str(std::string_view s) {
    u16(static_cast<std::uint16_t>(s.size()));
    out_.append(s.substr(0, 0xFFFF));
  }
  std::string& buffer() noexcept { return out_; }

 private:
  void uint(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
  }
  std::string out_;
};

/// Reads little-endian values from a byte buffer; every read is bounds-checked and a short buffer
/// throws IoError naming the source and the field being read.
class ByteReader {
 public:
  ByteReader(std::string_view data, std::string source) : data_(data), source_(std::move(source)) {}

  std::uint8_t u8(const char* what) { return static_cast<std::uint8_t>(uint(1, what)); }
  std::uint16_t u16(const char* what) { return static_cast<std::uint16_t>(uint(2, what)); }
  std::uint32_t u32(const char* what) { return static_cast<std::uint32_t>(uint(4, what)); }
  std::uint64_t u64(const char* what) { return uint(8, what); }
  std::int32_t i32(const char* what) { return static_cast<std::int32_t>(u32(what)); }
  float f32(const char* what) { return std::bit_cast<float>(u32(what)); }
  double f64(const char* what) { return std::bit_cast<double>(u64(what)); }
  /// An unsigned LEB128 varint (see ByteWriter::varint); more than 10 bytes or a value above
  /// 2^64 - 1 is corrupt.
  std::uint64_t varint(const char* what) {
    std::uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      need(1, what);
      const auto b = static_cast<std::uint8_t>(data_[pos_++]);
      if (shift == 63 && b > 1) break;
      v |= std::uint64_t{b & 0x7Fu} << shift;
      if ((b & 0x80u) == 0) return v;
    }
    fail(std::string("overlong varint in ") + what + " at byte " + std::to_string(pos_) + " (corrupt)");
  }
  /// A zigzag varint (see ByteWriter::svarint).
  std::int64_t svarint(const char* what) {
    const std::uint64_t u = varint(what);
    return static_cast<std::int64_t>(u >> 1) ^ -static_cast<std::int64_t>(u & 1u);
  }
  std::string_view bytes(std::size_t n, const char* what) {
    need(n, what);
    const std::string_view s = data_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  std::string str(std::size_t max_length, const char* what) {
    const std::size_t n = u16(what);
    if (n > max_length) fail(std::string(what) + " is " + std::to_string(n) + " bytes long (corrupt)");
    return std::string(bytes(n, what));
  }
  std::size_t position() const noexcept { return pos_; }
  std::size_t remaining() const noexcept { return data_.size() - pos_; }
  const std::string& source() const noexcept { return source_; }
  [[noreturn]] void fail(const std::string& what) const { throw IoError(source_ + ": " + what); }

 private:
  void need(std::size_t n, const char* what) const {
    if (remaining() < n) {
      fail(std::string("truncated file: ends while reading ") + what + " at byte " + std::to_string(pos_));
    }
  }
  std::uint64_t uint(int n, const char* what) {
    need(static_cast<std::size_t>(n), what);
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t{static_cast<std::uint8_t>(data_[pos_ + i])} << (8 * i);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }
  std::string_view data_;
  std::size_t pos_ = 0;
  std::string source_;
};

/// Reads a whole file into memory. \throws IoError naming the path if it cannot be read or is
/// larger than \p max_bytes.
inline std::string read_file_bytes(const std::string& path, std::uint64_t max_bytes = std::uint64_t{1} << 34) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) throw IoError("cannot open '" + path + "' for reading: " + std::strerror(errno));
  std::string out;
  char buf[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    out.append(buf, n);
    if (out.size() > max_bytes) {
      std::fclose(f);
      throw IoError("'" + path + "' is larger than the limit of " + std::to_string(max_bytes) + " bytes");
    }
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) throw IoError("reading '" + path + "' failed");
  return out;
}

}  // namespace intervox::detail
