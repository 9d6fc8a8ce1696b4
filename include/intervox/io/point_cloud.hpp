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
  if (t.kind == 'f') return t.size == 4 ? double(std::bit_cast<float>(static_cast<std::uint32_t>(bits))) : std::bit_cast<double>(bits);
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

/// Reads the vertices of a PLY file held in memory (every format; other elements are skipped).
/// \throws IoError naming \p source and the problem (bad header, no x/y/z, truncated data, bad number).
inline PointCloud read_ply_points_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  auto fail = [&](const std::string& what) -> void { throw IoError(source + ": PLY: " + what); };
  detail::LineReader lines(bytes);
  std::string_view line;
  if (!lines.next(line) || line != "ply") fail("not a PLY file (first line must be 'ply')");
  struct Property {
    std::string name;
    detail::ScalarType type;
    detail::ScalarType count_type;  // size 0 unless a list
  };
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
  };
  std::vector<Element> elements;
  std::string format;
  bool ended = false;
  while (!ended && lines.next(line)) {
    const auto words = detail::split_words(line);
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "format") {
      if (words.size() < 2) fail("bad format line");
      format = std::string(words[1]);
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") {
        fail("unknown format '" + detail::quote_bytes(format, 40) + "'");
      }
    } else if (words[0] == "element") {
      Element e;
      if (words.size() != 3 || !detail::parse_size(words[2], e.count)) fail("bad element line at line " + std::to_string(lines.line_number()));
      if (e.count > bytes.size()) fail("element count " + std::to_string(e.count) + " exceeds the file size");  // refined below
      e.name = std::string(words[1]);
      elements.push_back(std::move(e));
    } else if (words[0] == "property") {
      if (elements.empty()) fail("property before any element");
      Property p;
      if (words.size() == 5 && words[1] == "list") {
        p.count_type = detail::ply_type(words[2]);
        p.type = detail::ply_type(words[3]);
        p.name = std::string(words[4]);
        if (p.count_type.size == 0 || p.count_type.kind == 'f' || p.type.size == 0) fail("bad list property at line " + std::to_string(lines.line_number()));
      } else if (words.size() == 3) {
        p.type = detail::ply_type(words[1]);
        p.name = std::string(words[2]);
        if (p.type.size == 0) fail("unknown property type '" + detail::quote_bytes(words[1], 40) + "'");
      } else {
        fail("bad property line at line " + std::to_string(lines.line_number()));
      }
      elements.back().properties.push_back(std::move(p));
    } else if (words[0] == "end_header") {
      ended = true;
    } else {
      fail("unexpected header line '" + detail::quote_bytes(line, 40) + "'");
    }
  }
  if (!ended) fail("truncated header: no 'end_header'");
  if (format.empty()) fail("no format line");
  PointCloud cloud;
  const bool ascii = format == "ascii";
  const bool big = format == "binary_big_endian";
  std::size_t pos = lines.position();
  // ASCII tokens are read across line breaks; a vertex is one group of its properties.
  auto next_token = [&]() -> std::string_view {
    while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    const std::size_t s = pos;
    while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    if (pos == s) fail("truncated data");
    return bytes.substr(s, pos - s);
  };
  auto read_value = [&](detail::ScalarType t) -> double {
    if (ascii) {
      double v = 0;
      const std::string_view tok = next_token();
      if (!detail::parse_double(tok, v)) fail("bad number '" + detail::quote_bytes(tok, 40) + "'");
      return v;
    }
    if (bytes.size() - pos < static_cast<std::size_t>(t.size)) fail("truncated data");
    const double v = detail::read_scalar(bytes.data() + pos, t, big);
    pos += static_cast<std::size_t>(t.size);
    return v;
  };
  for (const Element& e : elements) {
    const bool vertex = e.name == "vertex";
    int ix = -1, iy = -1, iz = -1;
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const auto& n = e.properties[i].name;
      if (e.properties[i].count_type.size != 0) continue;
      if (n == "x") ix = static_cast<int>(i);
      if (n == "y") iy = static_cast<int>(i);
      if (n == "z") iz = static_cast<int>(i);
    }
    if (vertex && (ix < 0 || iy < 0 || iz < 0)) fail("the vertex element lacks x, y or z");
    // Check the count against what the rest of the file can hold before allocating for it: a
    // binary item takes at least its fixed-size properties and list lengths, an ASCII item at
    // least 2 bytes (a digit and a separator) per property.
    std::uint64_t min_item_bytes = 0;
    for (const Property& p : e.properties) {
      min_item_bytes += ascii ? 2u : static_cast<std::uint64_t>(p.count_type.size != 0 ? p.count_type.size : p.type.size);
    }
    const std::uint64_t rest = bytes.size() - pos + (ascii ? 1u : 0u);  // ASCII: the last value needs no separator
    if (min_item_bytes > 0 && e.count > rest / min_item_bytes) {
      fail("element '" + detail::quote_bytes(e.name, 40) + "' declares " + std::to_string(e.count) + " items of at least " +
           std::to_string(min_item_bytes) + " bytes (" + format + "), but only " + std::to_string(bytes.size() - pos) +
           " bytes follow the header (truncated or corrupt)");
    }
    if (vertex) cloud.points.reserve(static_cast<std::size_t>(e.count));
    double xyz[3] = {0, 0, 0};
    for (std::uint64_t item = 0; item < e.count; ++item) {
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (p.count_type.size != 0) {
          const double n = read_value(p.count_type);
          if (!(n >= 0 && n <= 1e6)) fail("bad list length");
          for (int j = 0; j < static_cast<int>(n); ++j) read_value(p.type);
          continue;
        }
        const double v = read_value(p.type);
        if (static_cast<int>(i) == ix) xyz[0] = v;
        if (static_cast<int>(i) == iy) xyz[1] = v;
        if (static_cast<int>(i) == iz) xyz[2] = v;
      }
      if (vertex) detail::add_point(cloud, xyz[0], xyz[1], xyz[2]);
    }
    if (vertex) return cloud;
  }
  fail("no vertex element");
  return cloud;
}

/// Reads a PCD file (DATA ascii or binary) held in memory.
/// \throws IoError naming \p source and the problem.
inline PointCloud read_pcd_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  auto fail = [&](const std::string& what) -> void { throw IoError(source + ": PCD: " + what); };
  detail::LineReader lines(bytes);
  std::string_view line;
  std::vector<std::string> fields;
  std::vector<int> sizes, counts;
  std::vector<char> types;
  std::uint64_t width = 0, height = 1, points = 0;
  bool have_points = false;
  std::string data;
  while (data.empty() && lines.next(line)) {
    const auto words = detail::split_words(line);
    if (words.empty() || words[0].front() == '#') continue;
    const std::string_view key = words[0];
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS") {
      for (std::size_t i = 1; i < words.size(); ++i) fields.emplace_back(words[i]);
    } else if (key == "SIZE" || key == "COUNT") {
      auto& v = key == "SIZE" ? sizes : counts;
      for (std::size_t i = 1; i < words.size(); ++i) {
        std::uint64_t n = 0;
        if (!detail::parse_size(words[i], n) || n == 0 || n > (key == "SIZE" ? 8u : 4096u)) fail("bad " + std::string(key));
        v.push_back(static_cast<int>(n));
      }
    } else if (key == "TYPE") {
      for (std::size_t i = 1; i < words.size(); ++i) {
        if (words[i].size() != 1 || std::string_view("IUF").find(words[i][0]) == std::string_view::npos) fail("bad TYPE");
        types.push_back(words[i][0]);
      }
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      std::uint64_t n = 0;
      if (words.size() != 2 || !detail::parse_size(words[1], n)) fail("bad " + std::string(key));
      (key == "WIDTH" ? width : key == "HEIGHT" ? height : points) = n;
      if (key == "POINTS") have_points = true;
    } else if (key == "DATA") {
      if (words.size() != 2) fail("bad DATA line");
      data = std::string(words[1]);
    } else {
      fail("unknown header line '" + detail::quote_bytes(line, 40) + "'");
    }
  }
  if (data.empty()) fail("truncated header: no DATA line");
  if (counts.empty()) counts.assign(fields.size(), 1);
  if (fields.empty() || sizes.size() != fields.size() || types.size() != fields.size() || counts.size() != fields.size()) {
    fail("FIELDS, SIZE, TYPE and COUNT disagree");
  }
  if (!have_points) {
    const auto product = checked_mul(width, height);
    if (!product) fail("bad WIDTH/HEIGHT: " + std::to_string(width) + " x " + std::to_string(height) + " overflows");
    points = *product;
  }
  if (points > bytes.size()) fail("POINTS " + std::to_string(points) + " exceeds the file size");
  int field_index[3] = {-1, -1, -1};
  std::size_t offset[3] = {0, 0, 0};
  std::size_t record = 0;
  std::size_t values = 0;
  std::size_t value_index[3] = {0, 0, 0};
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const int axis = fields[i] == "x" ? 0 : fields[i] == "y" ? 1 : fields[i] == "z" ? 2 : -1;
    if (types[i] == 'F' && sizes[i] != 4 && sizes[i] != 8) fail("float fields must have SIZE 4 or 8");
    if (types[i] != 'F' && sizes[i] != 1 && sizes[i] != 2 && sizes[i] != 4 && sizes[i] != 8) fail("bad integer SIZE");
    if (axis >= 0 && field_index[axis] < 0) {
      field_index[axis] = static_cast<int>(i);
      offset[axis] = record;
      value_index[axis] = values;
    }
    // sizes <= 8 and counts <= 4096 per field, but the number of fields is the file's: checked.
    const auto sum = checked_add(record, static_cast<std::size_t>(sizes[i]) * static_cast<std::size_t>(counts[i]));
    const auto n = checked_add(values, static_cast<std::size_t>(counts[i]));
    if (!sum || !n) fail("the record size of the FIELDS overflows");
    record = *sum;
    values = *n;
  }
  if (field_index[0] < 0 || field_index[1] < 0 || field_index[2] < 0) fail("FIELDS lack x, y or z");
  PointCloud cloud;
  if (data == "binary") {
    const std::size_t pos = lines.position();
    if (points > (bytes.size() - pos) / record) {
      fail("truncated data: " + std::to_string(points) + " points of " + std::to_string(record) + " bytes announced, " +
           std::to_string(bytes.size() - pos) + " bytes follow");
    }
    cloud.points.reserve(static_cast<std::size_t>(points));
    for (std::uint64_t i = 0; i < points; ++i) {
      const char* p = bytes.data() + pos + i * record;
      double xyz[3];
      for (int a = 0; a < 3; ++a) {
        const auto f = static_cast<std::size_t>(field_index[a]);
        const char kind = types[f] == 'F' ? 'f' : (types[f] == 'U' ? 'u' : 'i');
        xyz[a] = detail::read_scalar(p + offset[a], {sizes[f], kind}, false);
      }
      detail::add_point(cloud, xyz[0], xyz[1], xyz[2]);
    }
  } else if (data == "ascii") {
    // Each point takes at least 2 bytes (a digit and a separator) per value: check the count
    // against the bytes that follow before allocating for it.
    const std::uint64_t rest = bytes.size() - lines.position() + 1;
    if (points > rest / (2 * std::uint64_t{values})) {
      fail("truncated data: " + std::to_string(points) + " points of " + std::to_string(values) +
           " values announced, but only " + std::to_string(bytes.size() - lines.position()) +
           " bytes follow the header");
    }
    cloud.points.reserve(static_cast<std::size_t>(points));
    std::uint64_t read = 0;
    while (read < points && lines.next(line)) {
      const auto words = detail::split_words(line);
      if (words.empty()) continue;
      if (words.size() < values) fail("line " + std::to_string(lines.line_number()) + " has too few values");
      double xyz[3];
      for (int a = 0; a < 3; ++a) {
        if (!detail::parse_double(words[value_index[a]], xyz[a])) fail("bad number at line " + std::to_string(lines.line_number()));
      }
      detail::add_point(cloud, xyz[0], xyz[1], xyz[2]);
      ++read;
    }
    if (read < points) fail("truncated data: " + std::to_string(read) + " of " + std::to_string(points) + " points");
  } else {
    fail("DATA " + detail::quote_bytes(data, 40) + " is not supported (ascii or binary)");
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
      const std::string bytes = detail::read_file_bytes(path, detail::kDefaultReadLimitBytes, 4, [&](std::string_view magic) {
        if (magic != "ply\n" && magic != "ply\r") throw IoError(path + ": PLY: not a PLY file (first line must be 'ply')");
      });
      return read_ply_points_from_memory(bytes, path);
    }
    const std::string bytes = detail::read_file_bytes(path);
    return pcd ? read_pcd_from_memory(bytes, path) : read_xyz_from_memory(bytes, path);
  });
}

}  // namespace intervox
