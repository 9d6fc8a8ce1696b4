#pragma once
/// \file
/// Internal: one-shot zstd compression and bounded decompression (libzstd, linked through
/// intervox::intervox). Not part of the public API.

#include <intervox/io/detail/binary.hpp>

#include <zstd.h>

#include <cstdint>
#include <string>
#include <string_view>

namespace intervox::detail {

/// Compresses \p data as one zstd frame (with its content size) at \p level (1..19).
/// \throws IoError if libzstd fails.
inline std::string zstd_compress(std::string_view data, int level) {
  std::string out(ZSTD_compressBound(data.size()), '\0');
  const std::size_t n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), level);
  if (ZSTD_isError(n)) throw IoError(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

/// Decompresses \p frame, which must be exactly one zstd frame announcing \p size bytes of
/// content, into a buffer of exactly that size (the caller has checked \p size against its
/// budget). \throws IoError through \p r otherwise.
inline std::string zstd_decompress(std::string_view frame, std::uint64_t size, const ByteReader& r) {
  const unsigned long long announced = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (announced == ZSTD_CONTENTSIZE_ERROR || announced == ZSTD_CONTENTSIZE_UNKNOWN || announced != size) {
    r.fail("the compressed body is not a zstd frame of " + std::to_string(size) + " bytes (corrupt)");
  }
  const std::size_t frame_size = ZSTD_findFrameCompressedSize(frame.data(), frame.size());
  if (ZSTD_isError(frame_size) || frame_size != frame.size())
    r.fail("the compressed body is not one zstd frame (corrupt)");
  std::string out(static_cast<std::size_t>(size), '\0');
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), frame.data(), frame.size());
  if (ZSTD_isError(n) || n != size) {
    r.fail(std::string("the compressed body cannot be decompressed: ") +
           (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "wrong size") + " (corrupt)");
  }
  return out;
}

}  // namespace intervox::detail
