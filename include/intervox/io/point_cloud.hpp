#pragma once
/// \file
/// Point clouds in: PLY (ascii, binary little and big endian), PCD (ascii and binary) and XYZ
/// text, for inserting recorded data. Only the x, y, z coordinates are read.
///
/// Rules: points with a NaN or infinite coordinate (PCD marks invalid pixels of organised clouds
/// with NaN; "nan" and "inf" in text) are dropped and counted in PointCloud::dropped; every count
/// in a header is checked against what the bytes after the header can hold in the declared format
/// before anything is allocated (binary: the exact record size; ASCII: at least 2 bytes, a digit
/// and a separator, per value); numbers in text must be whole tokens within the range of double
/// ("1e400" and "1e400xyz" are refused, see detail/text.hpp); malformed files throw IoError naming
/// the file and the problem, with file content quoted with non-printable bytes as \xNN. PCD
/// `binary_compressed` is not supported (IoError).
/// Thread safety: the readers share no state; concurrent calls on different inputs are safe.

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/io/detail/binary.hpp>
#include <intervox/io/detail/text.hpp>
#include <intervox/io/load_budget.hpp>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <limits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace intervox {

/// Points read from a file.
struct PointCloud {
  std::vector<Point3> points;
  std::size_t dropped = 0;  ///< points skipped for a NaN or infinite coordinate
};

namespace detail {

/// Splits text into lines (without '\n' and a trailing '\r') from a position.
class LineReader {
 public:
  LineReader(std::string_view text, std::size_t pos = 0) : text_(text), pos_(pos) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(pos_, end - pos_);
    pos_ = std::min(text_.size(), end + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number_;
    return true;
  }
  std::size_t position() const noexcept { return pos_; }
  std::size_t line_number() const noexcept { return number_; }

 private:
  std::string_view text_;
  std::size_t pos_;
  std::size_t number_ = 0;
};

inline std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t s = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > s) out.push_back(line.substr(s, i - s));
  }
  return out;
}

/// A scalar type of PLY or PCD: byte size and kind (i = signed, u = unsigned, f = float).
struct ScalarType {
  int size = 0;
  char kind = 0;
};

/// Reads one scalar as double from little- or big-endian bytes (caller checked the length).
inline double read_scalar(const char* p, ScalarType t, bool big_endian) {
  std::uint64_t bits = 0;
  for (int i = 0; i < t.size; ++i) {
    const int at = big_endian ? t.size - 1 - i : i;
    bits |= std::uint64_t{static_cast<std::uint8_t>(p[at])} << (8 * i);
  }
  if (t.kind == 'f')
    return t.size == 4 ? double(std::bit_cast<float>(static_cast<std::uint32_t>(bits))) : std::bit_cast<double>(bits);
  if (t.kind == 'u') return static_cast<double>(bits);
  const int shift = 64 - 8 * t.size;
  return static_cast<double>(static_cast<std::int64_t>(bits << shift) >> shift);
}

inline void add_point(PointCloud& cloud, double x, double y, double z) {
  if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
    cloud.points.emplace_back(x, y, z);
  } else {
    ++cloud.dropped;
  }
}

inline ScalarType ply_type(std::string_view name) {
  if (name == "char" || name == "int8") return {1, 'i'};
  if (name == "uchar" || name == "uint8") return {1, 'u'};
  if (name == "short" || name == "int16") return {2, 'i'};
  if (name == "ushort" || name == "uint16") return {2, 'u'};
  if (name == "int" || name == "int32") return {4, 'i'};
  if (name == "uint" || name == "uint32") return {4, 'u'};
  if (name == "float" || name == "float32") return {4, 'f'};
  if (name == "double" || name == "float64") return {8, 'f'};
  return {};
}

}  // namespace detail

namespace detail {

/// Throws the IoError of the PLY reader: \p source, "PLY", then \p what.
[[noreturn]] inline void ply_fail(const std::string& source, const std::string& what) {
  throw IoError(source + ": PLY: " + what);
}

struct PlyProperty {
  std::string name;
  ScalarType type;
  ScalarType count_type;  // size 0 unless a list
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

/// A PLY header: its elements, its format and where the data begins.
struct PlyHeader {
  std::vector<PlyElement> elements;
  std::string format;
  std::size_t data_pos = 0;
};

/// Parses a "property" line (its words; \p line_number for messages).
inline PlyProperty parse_ply_property(const std::vector<std::string_view>& words, std::size_t line_number,
                                      const std::string& source) {
  PlyProperty p;
  if (words.size() == 5 && words[1] == "list") {
    p.count_type = ply_type(words[2]);
    p.type = ply_type(words[3]);
    p.name = std::string(words[4]);
    if (p.count_type.size == 0 || p.count_type.kind == 'f' || p.type.size == 0)
      ply_fail(source, "bad list property at line " + std::to_string(line_number));
  } else if (words.size() == 3) {
    p.type = ply_type(words[1]);
    p.name = std::string(words[2]);
    if (p.type.size == 0) ply_fail(source, "unknown property type '" + quote_bytes(words[1], 40) + "'");
  } else {
    ply_fail(source, "bad property line at line " + std::to_string(line_number));
  }
  return p;
}

/// Parses the header from "ply" to "end_header" (element counts checked against the file size).
inline PlyHeader parse_ply_header(std::string_view bytes, const std::string& source) {
  LineReader lines(bytes);
  std::string_view line;
  if (!lines.next(line) || line != "ply") ply_fail(source, "not a PLY file (first line must be 'ply')");
  PlyHeader h;
  bool ended = false;
  while (!ended && lines.next(line)) {
    const auto words = split_words(line);
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "format") {
      if (words.size() < 2) ply_fail(source, "bad format line");
      h.format = std::string(words[1]);
      if (h.format != "ascii" && h.format != "binary_little_endian" && h.format != "binary_big_endian") {
        ply_fail(source, "unknown format '" + quote_bytes(h.format, 40) + "'");
      }
    } else if (words[0] == "element") {
      PlyElement e;
      if (words.size() != 3 || !parse_size(words[2], e.count))
        ply_fail(source, "bad element line at line " + std::to_string(lines.line_number()));
      if (e.count > bytes.size())
        ply_fail(source, "element count " + std::to_string(e.count) + " exceeds the file size");  // refined below
      e.name = std::string(words[1]);
      h.elements.push_back(std::move(e));
    } else if (words[0] == "property") {
      if (h.elements.empty()) ply_fail(source, "property before any element");
      h.elements.back().properties.push_back(parse_ply_property(words, lines.line_number(), source));
    } else if (words[0] == "end_header") {
      ended = true;
    } else {
      ply_fail(source, "unexpected header line '" + quote_bytes(line, 40) + "'");
    }
  }
  if (!ended) ply_fail(source, "truncated header: no 'end_header'");
  if (h.format.empty()) ply_fail(source, "no format line");
  h.data_pos = lines.position();
  return h;
}

/// Reads the values of a PLY body in its format: ASCII tokens across line breaks, or binary scalars.
class PlyValueReader {
 public:
  PlyValueReader(std::string_view bytes, std::size_t pos, const std::string& format, const std::string& source)
      : bytes_(bytes), pos_(pos), ascii_(format == "ascii"), big_(format == "binary_big_endian"), source_(source) {}
  bool ascii() const noexcept { return ascii_; }
  std::size_t position() const noexcept { return pos_; }
  double read(ScalarType t) {
    if (ascii_) {
      double v = 0;
      const std::string_view tok = next_token();
      if (!parse_double(tok, v)) ply_fail(source_, "bad number '" + quote_bytes(tok, 40) + "'");
      return v;
    }
    if (bytes_.size() - pos_ < static_cast<std::size_t>(t.size)) ply_fail(source_, "truncated data");
    const double v = read_scalar(bytes_.data() + pos_, t, big_);
    pos_ += static_cast<std::size_t>(t.size);
    return v;
  }

 private:
  std::string_view next_token() {
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    const std::size_t s = pos_;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    if (pos_ == s) ply_fail(source_, "truncated data");
    return bytes_.substr(s, pos_ - s);
  }

  std::string_view bytes_;
  std::size_t pos_;
  bool ascii_;
  bool big_;
  const std::string& source_;
};

/// Checks an element's count against what the rest of the file can hold before allocating for
/// it: a binary item takes at least its fixed-size properties and list lengths, an ASCII item at
/// least 2 bytes (a digit and a separator) per property.
inline void check_ply_element_count(const PlyElement& e, const PlyValueReader& in, std::size_t file_size,
                                    const std::string& format, const std::string& source) {
  std::uint64_t min_item_bytes = 0;
  for (const PlyProperty& p : e.properties) {
    min_item_bytes +=
        in.ascii() ? 2u : static_cast<std::uint64_t>(p.count_type.size != 0 ? p.count_type.size : p.type.size);
  }
  const std::uint64_t rest =
      file_size - in.position() + (in.ascii() ? 1u : 0u);  // ASCII: the last value needs no separator
  if (min_item_bytes > 0 && e.count > rest / min_item_bytes) {
    ply_fail(source, "element '" + quote_bytes(e.name, 40) + "' declares " + std::to_string(e.count) +
                         " items of at least " + std::to_string(min_item_bytes) + " bytes (" + format + "), but only " +
                         std::to_string(file_size - in.position()) + " bytes follow the header (truncated or corrupt)");
  }
}

/// Reads the items of element \p e; the points of the vertex element go to \p cloud. Returns
/// whether \p e is the vertex element.
inline bool read_ply_element(const PlyElement& e, PlyValueReader& in, std::size_t file_size, const std::string& format,
                             PointCloud& cloud, const std::string& source) {
  const bool vertex = e.name == "vertex";
  int ix = -1, iy = -1, iz = -1;
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    const auto& n = e.properties[i].name;
    if (e.properties[i].count_type.size != 0) continue;
    if (n == "x") ix = static_cast<int>(i);
    if (n == "y") iy = static_cast<int>(i);
    if (n == "z") iz = static_cast<int>(i);
  }
  if (vertex && (ix < 0 || iy < 0 || iz < 0)) ply_fail(source, "the vertex element lacks x, y or z");
  check_ply_element_count(e, in, file_size, format, source);
  if (vertex) cloud.points.reserve(static_cast<std::size_t>(e.count));
  double xyz[3] = {0, 0, 0};
  for (std::uint64_t item = 0; item < e.count; ++item) {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      if (p.count_type.size != 0) {
        const double n = in.read(p.count_type);
        if (!(n >= 0 && n <= 1e6)) ply_fail(source, "bad list length");
        for (int j = 0; j < static_cast<int>(n); ++j) in.read(p.type);
        continue;
      }
      const double v = in.read(p.type);
      if (static_cast<int>(i) == ix) xyz[0] = v;
      if (static_cast<int>(i) == iy) xyz[1] = v;
      if (static_cast<int>(i) == iz) xyz[2] = v;
    }
    if (vertex) add_point(cloud, xyz[0], xyz[1], xyz[2]);
  }
  return vertex;
}

}  // namespace detail

/// Reads the vertices of a PLY file held in memory (every format; other elements are skipped).
/// \throws IoError naming \p source and the problem (bad header, no x/y/z, truncated data, bad number).
inline PointCloud read_ply_points_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  const detail::PlyHeader header = detail::parse_ply_header(bytes, source);
  PointCloud cloud;
  detail::PlyValueReader in(bytes, header.data_pos, header.format, source);
  for (const detail::PlyElement& e : header.elements) {
    if (detail::read_ply_element(e, in, bytes.size(), header.format, cloud, source)) return cloud;
  }
  detail::ply_fail(source, "no vertex element");
}

namespace detail {

/// Throws the IoError of the PCD reader: \p source, "PCD", then \p what.
[[noreturn]] inline void pcd_fail(const std::string& source, const std::string& what) {
  throw IoError(source + ": PCD: " + what);
}

/// A PCD header as read (before its checks).
struct PcdHeader {
  std::vector<std::string> fields;
  std::vector<int> sizes, counts;
  std::vector<char> types;
  std::uint64_t width = 0, height = 1, points = 0;
  bool have_points = false;
  std::string data;
};

/// Reads the header lines up to DATA (or the end of \p lines).
inline PcdHeader parse_pcd_header(LineReader& lines, const std::string& source) {
  PcdHeader h;
  std::string_view line;
  while (h.data.empty() && lines.next(line)) {
    const auto words = split_words(line);
    if (words.empty() || words[0].front() == '#') continue;
    const std::string_view key = words[0];
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS") {
      for (std::size_t i = 1; i < words.size(); ++i) h.fields.emplace_back(words[i]);
    } else if (key == "SIZE" || key == "COUNT") {
      auto& v = key == "SIZE" ? h.sizes : h.counts;
      for (std::size_t i = 1; i < words.size(); ++i) {
        std::uint64_t n = 0;
        if (!parse_size(words[i], n) || n == 0 || n > (key == "SIZE" ? 8u : 4096u))
          pcd_fail(source, "bad " + std::string(key));
        v.push_back(static_cast<int>(n));
      }
    } else if (key == "TYPE") {
      for (std::size_t i = 1; i < words.size(); ++i) {
        if (words[i].size() != 1 || std::string_view("IUF").find(words[i][0]) == std::string_view::npos)
          pcd_fail(source, "bad TYPE");
        h.types.push_back(words[i][0]);
      }
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      std::uint64_t n = 0;
      if (words.size() != 2 || !parse_size(words[1], n)) pcd_fail(source, "bad " + std::string(key));
      (key == "WIDTH" ? h.width : key == "HEIGHT" ? h.height : h.points) = n;
      if (key == "POINTS") h.have_points = true;
    } else if (key == "DATA") {
      if (words.size() != 2) pcd_fail(source, "bad DATA line");
      h.data = std::string(words[1]);
    } else {
      pcd_fail(source, "unknown header line '" + quote_bytes(line, 40) + "'");
    }
  }
  return h;
}

/// Checks a header read: a DATA line, FIELDS, SIZE, TYPE and COUNT (by default 1 each) in
/// agreement, and the point count (by default WIDTH x HEIGHT) within the file size.
inline void check_pcd_header(PcdHeader& h, std::size_t file_size, const std::string& source) {
  if (h.data.empty()) pcd_fail(source, "truncated header: no DATA line");
  if (h.counts.empty()) h.counts.assign(h.fields.size(), 1);
  if (h.fields.empty() || h.sizes.size() != h.fields.size() || h.types.size() != h.fields.size() ||
      h.counts.size() != h.fields.size()) {
    pcd_fail(source, "FIELDS, SIZE, TYPE and COUNT disagree");
  }
  if (!h.have_points) {
    const auto product = checked_mul(h.width, h.height);
    if (!product)
      pcd_fail(source,
               "bad WIDTH/HEIGHT: " + std::to_string(h.width) + " x " + std::to_string(h.height) + " overflows");
    h.points = *product;
  }
  if (h.points > file_size) pcd_fail(source, "POINTS " + std::to_string(h.points) + " exceeds the file size");
}

/// Where x, y and z lie in a PCD point: field, byte offset in a binary record, value in an ASCII line.
struct PcdLayout {
  int field_index[3] = {-1, -1, -1};
  std::size_t offset[3] = {0, 0, 0};
  std::size_t record = 0;  ///< bytes of a binary record
  std::size_t values = 0;  ///< values of an ASCII line
  std::size_t value_index[3] = {0, 0, 0};
};

/// The layout of the fields (the first x, y and z count).
/// \throws IoError for a bad SIZE, a record size that overflows, or no x, y or z.
inline PcdLayout pcd_layout(const PcdHeader& h, const std::string& source) {
  PcdLayout l;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    const int axis = h.fields[i] == "x" ? 0 : h.fields[i] == "y" ? 1 : h.fields[i] == "z" ? 2 : -1;
    if (h.types[i] == 'F' && h.sizes[i] != 4 && h.sizes[i] != 8) pcd_fail(source, "float fields must have SIZE 4 or 8");
    if (h.types[i] != 'F' && h.sizes[i] != 1 && h.sizes[i] != 2 && h.sizes[i] != 4 && h.sizes[i] != 8)
      pcd_fail(source, "bad integer SIZE");
    if (axis >= 0 && l.field_index[axis] < 0) {
      l.field_index[axis] = static_cast<int>(i);
      l.offset[axis] = l.record;
      l.value_index[axis] = l.values;
    }
    // sizes <= 8 and counts <= 4096 per field, but the number of fields is the file's: checked.
    const auto sum =
        checked_add(l.record, static_cast<std::size_t>(h.sizes[i]) * static_cast<std::size_t>(h.counts[i]));
    const auto n = checked_add(l.values, static_cast<std::size_t>(h.counts[i]));
    if (!sum || !n) pcd_fail(source, "the record size of the FIELDS overflows");
    l.record = *sum;
    l.values = *n;
  }
  if (l.field_index[0] < 0 || l.field_index[1] < 0 || l.field_index[2] < 0) pcd_fail(source, "FIELDS lack x, y or z");
  return l;
}

/// Reads the binary records from \p pos (their number checked against the bytes first).
inline void read_pcd_binary(std::string_view bytes, std::size_t pos, const PcdHeader& h, const PcdLayout& l,
                            PointCloud& cloud, const std::string& source) {
  if (h.points > (bytes.size() - pos) / l.record) {
    pcd_fail(source, "truncated data: " + std::to_string(h.points) + " points of " + std::to_string(l.record) +
                         " bytes announced, " + std::to_string(bytes.size() - pos) + " bytes follow");
  }
  cloud.points.reserve(static_cast<std::size_t>(h.points));
  for (std::uint64_t i = 0; i < h.points; ++i) {
    const char* p = bytes.data() + pos + i * l.record;
    double xyz[3];
    for (int a = 0; a < 3; ++a) {
      const auto f = static_cast<std::size_t>(l.field_index[a]);
      const char kind = h.types[f] == 'F' ? 'f' : (h.types[f] == 'U' ? 'u' : 'i');
      xyz[a] = read_scalar(p + l.offset[a], {h.sizes[f], kind}, false);
    }
    add_point(cloud, xyz[0], xyz[1], xyz[2]);
  }
}

/// Reads the ASCII lines that follow the header in \p lines (their number checked against the
/// bytes first: each point takes at least 2 bytes, a digit and a separator, per value).
inline void read_pcd_ascii(std::string_view bytes, LineReader& lines, const PcdHeader& h, const PcdLayout& l,
                           PointCloud& cloud, const std::string& source) {
  const std::uint64_t rest = bytes.size() - lines.position() + 1;
  if (h.points > rest / (2 * std::uint64_t{l.values})) {
    pcd_fail(source, "truncated data: " + std::to_string(h.points) + " points of " + std::to_string(l.values) +
                         " values announced, but only " + std::to_string(bytes.size() - lines.position()) +
                         " bytes follow the header");
  }
  cloud.points.reserve(static_cast<std::size_t>(h.points));
  std::uint64_t read = 0;
  std::string_view line;
  while (read < h.points && lines.next(line)) {
    const auto words = split_words(line);
    if (words.empty()) continue;
    if (words.size() < l.values)
      pcd_fail(source, "line " + std::to_string(lines.line_number()) + " has too few values");
    double xyz[3];
    for (int a = 0; a < 3; ++a) {
      if (!parse_double(words[l.value_index[a]], xyz[a]))
        pcd_fail(source, "bad number at line " + std::to_string(lines.line_number()));
    }
    add_point(cloud, xyz[0], xyz[1], xyz[2]);
    ++read;
  }
  if (read < h.points)
    pcd_fail(source, "truncated data: " + std::to_string(read) + " of " + std::to_string(h.points) + " points");
}

}  // namespace detail

/// Reads a PCD file (DATA ascii or binary) held in memory.
/// \throws IoError naming \p source and the problem.
inline PointCloud read_pcd_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  detail::LineReader lines(bytes);
  detail::PcdHeader header = detail::parse_pcd_header(lines, source);
  detail::check_pcd_header(header, bytes.size(), source);
  const detail::PcdLayout layout = detail::pcd_layout(header, source);
  PointCloud cloud;
  if (header.data == "binary") {
    detail::read_pcd_binary(bytes, lines.position(), header, layout, cloud, source);
  } else if (header.data == "ascii") {
    detail::read_pcd_ascii(bytes, lines, header, layout, cloud, source);
  } else {
    detail::pcd_fail(source, "DATA " + detail::quote_bytes(header.data, 40) + " is not supported (ascii or binary)");
  }
  return cloud;
}

/// Reads an XYZ text file held in memory: one point per line, the first three numbers of each
/// line (further columns such as colours or normals are ignored); blank lines and lines starting
/// with '#' or "//" are skipped.
/// \throws IoError naming \p source and the line of the first malformed line.
inline PointCloud read_xyz_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  detail::LineReader lines(bytes);
  std::string_view line;
  PointCloud cloud;
  while (lines.next(line)) {
    std::string text(line);
    for (char& c : text) {
      if (c == ',' || c == ';') c = ' ';
    }
    const auto words = detail::split_words(text);
    if (words.empty() || words[0].front() == '#' || words[0].substr(0, 2) == "//") continue;
    double xyz[3];
    if (words.size() < 3 || !detail::parse_double(words[0], xyz[0]) || !detail::parse_double(words[1], xyz[1]) ||
        !detail::parse_double(words[2], xyz[2])) {
      throw IoError(source + ": XYZ: line " + std::to_string(lines.line_number()) + " is not 'x y z ...'");
    }
    detail::add_point(cloud, xyz[0], xyz[1], xyz[2]);
  }
  return cloud;
}

/// Reads a point cloud file, choosing the format by extension: .ply, .pcd, .xyz (also .txt, .pts
/// as XYZ), case-insensitive. The file must be a regular file of at most
/// detail::kDefaultReadLimitBytes (1 GiB); a PLY file is refused after its first 4 bytes if they
/// are not "ply\n" (or "ply\r").
/// \throws IoError for an unknown extension, an unreadable file, one that is not a regular file
///   (a directory, a device, a FIFO) or is over the limit, a malformed one, and an allocation
///   failure (never std::bad_alloc).
inline PointCloud read_point_cloud(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool ply = ext == "ply", pcd = ext == "pcd", xyz = ext == "xyz" || ext == "txt" || ext == "pts";
  if (!ply && !pcd && !xyz) throw IoError(path + ": unknown point cloud extension (expected .ply, .pcd or .xyz)");
  return detail::guard_allocation(path, [&]() -> PointCloud {
    if (ply) {
      const std::string bytes =
          detail::read_file_bytes(path, detail::kDefaultReadLimitBytes, 4, [&](std::string_view magic) {
            if (magic != "ply\n" && magic != "ply\r")
              throw IoError(path + ": PLY: not a PLY file (first line must be 'ply')");
          });
      return read_ply_points_from_memory(bytes, path);
    }
    const std::string bytes = detail::read_file_bytes(path);
    return pcd ? read_pcd_from_memory(bytes, path) : read_xyz_from_memory(bytes, path);
  });
}

}  // namespace intervox
