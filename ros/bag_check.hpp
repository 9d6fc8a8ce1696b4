#pragma once
// A check of a ROS bag's structure before rosbag_storage reads it (intervox_bag): rosbag_storage
// trusts the sizes a bag's records declare, and a corrupt one (a chunk that claims 1.29 GB, a record
// longer than its chunk) makes it allocate what the record claims and fail an assertion, which
// aborts the process. check_bag() walks the bag itself, as the format documents it
// (wiki.ros.org/Bags/Format/2.0), and throws intervox::IoError naming the bag, the byte offset and
// the problem before the library sees anything a record claims beyond the file or the budget:
//  - the version line "#ROSBAG V2.0" (other versions, 1.2, are left to the library);
//  - every record of the file: its header length and data length within the bytes that follow,
//    every header field "name=value" within its header, an "op" field of one byte;
//  - the bag header (op 3): its index position within the file;
//  - every chunk (op 5): a known compression (none, lz4, bz2), an uncompressed size within
//    max_chunk_bytes (and equal to the data for "none"); its data uncompressed to exactly that size
//    (roslz4, libbz2), and every record inside (messages, op 2, and connections, op 7) within it;
//  - every index record (op 4) after a chunk: data of count x 12 bytes, each offset within that
//    chunk; every chunk info record (op 6): data of count x 8 bytes, its chunk position that of a
//    chunk of the file; connection records (op 7) with their header within their data.
// Memory: one chunk, compressed and uncompressed, at a time (at most twice max_chunk_bytes).
#include <intervox/core/error.hpp>

#include <roslz4/lz4s.h>

#include <bzlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace intervox_ros {

/// What check_bag() accepts.
struct BagCheckOptions {
  /// The largest uncompressed chunk: rosbag_storage holds one chunk in memory at a time (a chunk
  /// holds at least one message; rosbag writes chunks of 768 KiB unless a message is larger).
  std::uint64_t max_chunk_bytes = std::uint64_t{512} << 20;
};

/// What check_bag() found.
struct BagCheckSummary {
  bool checked = false;  ///< false: not a version 2.0 bag, left to rosbag_storage
  std::uint64_t records = 0, chunks = 0, messages = 0, connections = 0;
};

namespace bag_detail {

/// One record's header fields ("name" -> "value" bytes).
using Fields = std::map<std::string, std::string, std::less<>>;

inline std::uint32_t u32(std::string_view b) noexcept {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[static_cast<std::size_t>(i)]);
  return v;
}
inline std::uint64_t u64(std::string_view b) noexcept {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[static_cast<std::size_t>(i)]);
  return v;
}

/// Reports the first problem: IoError "<bag>: byte <offset>: <what>".
class Failer {
 public:
  explicit Failer(std::string bag) : bag_(std::move(bag)) {}
  [[noreturn]] void operator()(std::uint64_t at, const std::string& what) const {
    throw intervox::IoError("the bag '" + bag_ + "' is corrupt at byte " + std::to_string(at) + ": " + what +
                            " (rosbag_storage would trust it and may abort; intervox_bag refuses the bag)");
  }

 private:
  std::string bag_;
};

/// Parses the header \p h of the record at \p at into fields.
inline Fields parse_header(std::string_view h, std::uint64_t at, const Failer& fail) {
  Fields f;
  std::size_t pos = 0;
  while (pos < h.size()) {
    if (h.size() - pos < 4) fail(at, "a header field's length is cut off");
    const std::uint32_t len = u32(h.substr(pos, 4));
    pos += 4;
    if (len > h.size() - pos)
      fail(at, "a header field claims " + std::to_string(len) + " bytes, its header holds " +
                   std::to_string(h.size() - pos));
    const std::string_view field = h.substr(pos, len);
    pos += len;
    const std::size_t eq = field.find('=');
    if (eq == std::string_view::npos) fail(at, "a header field without '='");
    f.emplace(std::string(field.substr(0, eq)), std::string(field.substr(eq + 1)));
  }
  return f;
}

inline const std::string& field(const Fields& f, const char* name, std::size_t size, std::uint64_t at,
                                const Failer& fail) {
  const auto it = f.find(name);
  if (it == f.end()) fail(at, std::string("the record has no '") + name + "' field");
  if (size != 0 && it->second.size() != size)
    fail(at, std::string("the field '") + name + "' holds " + std::to_string(it->second.size()) + " bytes, not " +
                 std::to_string(size));
  return it->second;
}

inline std::uint8_t op_of(const Fields& f, std::uint64_t at, const Failer& fail) {
  return static_cast<std::uint8_t>(field(f, "op", 1, at, fail)[0]);
}

/// Walks the records inside an uncompressed chunk \p data (starting at file offset \p at):
/// messages (op 2) and connections (op 7) only, each within the chunk.
inline void check_chunk_records(std::string_view data, std::uint64_t at, BagCheckSummary& s, const Failer& fail) {
  std::size_t pos = 0;
  while (pos < data.size()) {
    if (data.size() - pos < 4) fail(at, "a record inside the chunk is cut off at its header length");
    const std::uint32_t hlen = u32(data.substr(pos, 4));
    if (hlen > data.size() - pos - 4)
      fail(at, "a record at byte " + std::to_string(pos) + " of the chunk claims a header of " + std::to_string(hlen) +
                   " bytes, the chunk holds " + std::to_string(data.size() - pos - 4) + " more");
    const Fields f = parse_header(data.substr(pos + 4, hlen), at, fail);
    pos += 4 + hlen;
    if (data.size() - pos < 4) fail(at, "a record inside the chunk is cut off at its data length");
    const std::uint32_t dlen = u32(data.substr(pos, 4));
    if (dlen > data.size() - pos - 4)
      fail(at, "a record inside the chunk claims " + std::to_string(dlen) + " bytes of data, the chunk holds " +
                   std::to_string(data.size() - pos - 4) + " more");
    pos += 4 + dlen;
    const std::uint8_t op = op_of(f, at, fail);
    if (op == 2) {
      (void)field(f, "conn", 4, at, fail);
      (void)field(f, "time", 8, at, fail);
      ++s.messages;
    } else if (op == 7) {
      (void)field(f, "conn", 4, at, fail);
      (void)field(f, "topic", 0, at, fail);
    } else {
      fail(at, "a record of op " + std::to_string(op) + " inside a chunk (only messages and connections belong there)");
    }
  }
}

}  // namespace bag_detail

/// Checks the bag at \p path (see the file comment) before rosbag_storage reads it.
/// \throws intervox::IoError naming the bag, the byte offset and the problem.
inline BagCheckSummary check_bag(const std::string& path, const BagCheckOptions& options = {}) {
  using namespace bag_detail;
  const Failer fail(path);
  BagCheckSummary s;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw intervox::IoError("cannot open the bag '" + path + "'");
  struct Closer {
    std::FILE* f;
    ~Closer() { std::fclose(f); }
  } closer{file};
  if (std::fseek(file, 0, SEEK_END) != 0) throw intervox::IoError("cannot read the bag '" + path + "'");
  const long end = std::ftell(file);
  if (end < 0 || std::fseek(file, 0, SEEK_SET) != 0) throw intervox::IoError("cannot read the bag '" + path + "'");
  const auto size = static_cast<std::uint64_t>(end);
  std::uint64_t pos = 0;
  const auto read = [&](std::uint64_t n, std::string& out, const char* what) {
    out.resize(static_cast<std::size_t>(n));
    if (n > 0 && std::fread(out.data(), 1, out.size(), file) != out.size())
      fail(pos, std::string("cannot read ") + what);
    pos += n;
  };
  std::string buf;
  static constexpr std::string_view kMagic = "#ROSBAG V2.0\n";
  if (size < kMagic.size()) return s;  // (too short for a bag: rosbag_storage says so)
  read(kMagic.size(), buf, "the version line");
  if (buf != kMagic) return s;  // another version, or no bag: rosbag_storage's own message
  s.checked = true;
  constexpr std::uint64_t kMaxHeader = std::uint64_t{16} << 20;  // message definitions are kilobytes
  std::set<std::uint64_t> chunk_positions;
  std::vector<std::uint64_t> chunk_infos;  // (position of each chunk info's chunk)
  std::optional<std::uint64_t> last_chunk_size;
  std::string data, plain;
  while (pos < size) {
    const std::uint64_t at = pos;
    ++s.records;
    if (size - pos < 4) fail(at, "a record is cut off at its header length");
    read(4, buf, "a header length");
    const std::uint32_t hlen = u32(buf);
    if (hlen > size - pos || hlen > kMaxHeader)
      fail(at, "a record claims a header of " + std::to_string(hlen) + " bytes, " + std::to_string(size - pos) +
                   " bytes follow in the file");
    read(hlen, buf, "a record header");
    const Fields f = parse_header(buf, at, fail);
    if (size - pos < 4) fail(at, "a record is cut off at its data length");
    read(4, buf, "a data length");
    const std::uint32_t dlen = u32(buf);
    if (dlen > size - pos)
      fail(at, "a record claims " + std::to_string(dlen) + " bytes of data, " + std::to_string(size - pos) +
                   " bytes follow in the file");
    const std::uint8_t op = op_of(f, at, fail);
    if (op == 5) {  // chunk
      const std::string& compression = field(f, "compression", 0, at, fail);
      const std::uint32_t usize = u32(field(f, "size", 4, at, fail));
      if (usize > options.max_chunk_bytes)
        fail(at, "a chunk claims " + std::to_string(usize) + " bytes uncompressed, more than the budget of " +
                     std::to_string(options.max_chunk_bytes >> 20) + " MiB (--max-chunk-mib)");
      if (dlen > options.max_chunk_bytes + 1024 + options.max_chunk_bytes / 64)
        fail(at, "a chunk of " + std::to_string(dlen) + " compressed bytes, more than the budget allows");
      read(dlen, data, "a chunk");
      if (compression == "none") {
        if (usize != dlen)
          fail(at,
               "an uncompressed chunk claims " + std::to_string(usize) + " bytes and holds " + std::to_string(dlen));
        check_chunk_records(data, at, s, fail);
      } else if (compression == "lz4" || compression == "bz2") {
        plain.assign(usize, '\0');
        unsigned int got = usize;
        const bool ok = compression == "lz4"
                            ? roslz4_buffToBuffDecompress(data.data(), static_cast<unsigned>(data.size()), plain.data(),
                                                          &got) == ROSLZ4_OK
                            : BZ2_bzBuffToBuffDecompress(plain.data(), &got, data.data(),
                                                         static_cast<unsigned>(data.size()), 0, 0) == BZ_OK;
        if (!ok || got != usize)
          fail(at, "a " + compression + " chunk that claims " + std::to_string(usize) +
                       " bytes does not decompress to that size");
        check_chunk_records(plain, at, s, fail);
      } else {
        fail(at, "a chunk compressed with '" + compression + "' (expected none, lz4 or bz2)");
      }
      chunk_positions.insert(at);
      last_chunk_size = usize;
      ++s.chunks;
      continue;
    }
    read(dlen, data, "a record's data");
    switch (op) {
      case 3: {  // bag header
        const std::uint64_t index = u64(field(f, "index_pos", 8, at, fail));
        if (index > size)
          fail(at, "the bag header's index position " + std::to_string(index) + " lies beyond the file");
        (void)field(f, "conn_count", 4, at, fail);
        (void)field(f, "chunk_count", 4, at, fail);
        break;
      }
      case 4: {  // index data of the chunk before it
        const std::uint32_t count = u32(field(f, "count", 4, at, fail));
        (void)field(f, "conn", 4, at, fail);
        if (std::uint64_t{count} * 12 != dlen)
          fail(at, "an index record of " + std::to_string(count) + " entries holds " + std::to_string(dlen) + " bytes");
        if (!last_chunk_size) fail(at, "an index record before any chunk");
        for (std::uint32_t i = 0; i < count; ++i)
          if (u32(std::string_view(data).substr(std::size_t{i} * 12 + 8, 4)) >= *last_chunk_size)
            fail(at, "an index entry points beyond its chunk");
        break;
      }
      case 6: {  // chunk info
        const std::uint32_t count = u32(field(f, "count", 4, at, fail));
        if (std::uint64_t{count} * 8 != dlen)
          fail(at, "a chunk info record of " + std::to_string(count) + " connections holds " + std::to_string(dlen) +
                       " bytes");
        chunk_infos.push_back(u64(field(f, "chunk_pos", 8, at, fail)));
        break;
      }
      case 7: {  // connection (the index section's copy)
        (void)field(f, "conn", 4, at, fail);
        (void)field(f, "topic", 0, at, fail);
        (void)parse_header(data, at, fail);  // the connection header
        ++s.connections;
        break;
      }
      case 2:
        fail(at, "a message record outside any chunk");
      default:
        fail(at, "a record of unknown op " + std::to_string(op));
    }
  }
  for (const std::uint64_t c : chunk_infos)
    if (!chunk_positions.contains(c))
      fail(c, "a chunk info record points at " + std::to_string(c) + ", where no chunk starts");
  return s;
}

}  // namespace intervox_ros
