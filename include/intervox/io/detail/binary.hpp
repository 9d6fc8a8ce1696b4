#pragma once
/// \file
/// Internal: little-endian encoding, CRC-32 and a bounds-checked reader over a byte buffer.
/// Not part of the public API.

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/path.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
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

/// Default limit of read_file_bytes: 1 GiB, far above any map, cloud or run file of the examples
/// and below the memory of the machines Intervox runs on. A caller that needs more passes its own.
inline constexpr std::uint64_t kDefaultReadLimitBytes = std::uint64_t{1} << 30;

/// What kind of file a stat mode names, for error messages ("a directory", "a FIFO", ...).
inline const char* file_kind(mode_t mode) noexcept {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// A file open for reading that is known to be a regular file (closed on destruction).
class InputFile {
 public:
  /// Opens \p path. Directories, devices (/dev/zero), FIFOs and sockets are refused before a byte
  /// is read: they have no size and some never end. The open does not block on a FIFO.
  /// \throws IoError naming the path if it cannot be opened or is not a regular file.
  explicit InputFile(const std::string& path) : path_(path) {
    check_path(path);  // a NUL would make open() read another, shorter name
    if (path.find('\0') != std::string::npos) throw IoError("cannot open a path containing a NUL byte for reading");
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd < 0) throw IoError("cannot open '" + path + "' for reading: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
      const int error = errno;
      ::close(fd);
      throw IoError("cannot read '" + path + "': " + std::strerror(error));
    }
    if (!S_ISREG(st.st_mode)) {
      ::close(fd);
      throw IoError("cannot read '" + path + "': it is " + file_kind(st.st_mode) + ", not a regular file");
    }
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    size_ = static_cast<std::uint64_t>(st.st_size);
    file_ = ::fdopen(fd, "rb");
    if (file_ == nullptr) {
      const int error = errno;
      ::close(fd);
      throw IoError("cannot read '" + path + "': " + std::strerror(error));
    }
  }
  ~InputFile() { std::fclose(file_); }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  std::FILE* get() const noexcept { return file_; }
  /// The size the file had when it was opened.
  std::uint64_t size() const noexcept { return size_; }
  const std::string& path() const noexcept { return path_; }

  /// Appends up to \p n more bytes to \p out (fewer at the end of the file).
  /// \throws IoError if reading fails.
  void read_into(std::string& out, std::uint64_t n) {
    char buf[1 << 16];
    while (n > 0) {
      const std::size_t want = n < sizeof buf ? static_cast<std::size_t>(n) : sizeof buf;
      const std::size_t got = std::fread(buf, 1, want, file_);
      out.append(buf, got);
      n -= got;
      if (got < want) break;
    }
    if (std::ferror(file_) != 0) throw IoError("reading '" + path_ + "' failed");
  }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::uint64_t size_ = 0;
};

/// Reads a whole regular file into memory, refusing more than \p max_bytes: a file whose size is
/// over the limit is refused before anything is read, and reading stops at the limit if the file
/// grows meanwhile. If \p check_prefix is given, the first \p prefix_bytes (fewer for a shorter
/// file) are read first and passed to it, so that a loader refuses a foreign file by its magic
/// after reading only those bytes (check_prefix throws to refuse).
/// \throws IoError naming the path if it cannot be opened, is not a regular file (a directory, a
///   device, a FIFO), is larger than \p max_bytes or cannot be read; whatever check_prefix throws.
template <class CheckPrefix>
std::string read_file_bytes(const std::string& path, std::uint64_t max_bytes, std::size_t prefix_bytes,
                            CheckPrefix&& check_prefix) {
  InputFile file(path);
  std::string out;
  if (prefix_bytes > 0) {
    file.read_into(out, prefix_bytes);
    check_prefix(std::string_view(out));
  }
  if (file.size() > max_bytes) {
    throw IoError("'" + path + "' is " + std::to_string(file.size()) + " bytes, larger than the limit of " +
                  std::to_string(max_bytes) + " bytes for this kind of file");
  }
  out.reserve(static_cast<std::size_t>(file.size()));
  file.read_into(out, saturating_add(max_bytes - std::min<std::uint64_t>(out.size(), max_bytes), std::uint64_t{1}));
  if (out.size() > max_bytes) {
    throw IoError("'" + path + "' grew beyond the limit of " + std::to_string(max_bytes) + " bytes while being read");
  }
  return out;
}

/// Reads a whole regular file into memory (see the overload with a prefix check), at most
/// \p max_bytes (default kDefaultReadLimitBytes, 1 GiB).
/// \throws IoError as that overload.
inline std::string read_file_bytes(const std::string& path, std::uint64_t max_bytes = kDefaultReadLimitBytes) {
  return read_file_bytes(path, max_bytes, 0, [](std::string_view) {});
}

/// Reads at most the first \p n bytes of a regular file (all of a shorter one), e.g. a header.
/// \throws IoError as read_file_bytes.
inline std::string read_file_prefix(const std::string& path, std::size_t n) {
  InputFile file(path);
  std::string out;
  file.read_into(out, n);
  return out;
}

}  // namespace intervox::detail
