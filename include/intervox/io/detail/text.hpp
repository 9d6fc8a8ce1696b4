#pragma once
/// \file
/// Internal: strict number parsing of text tokens from files, and quoting of file content in
/// error messages. Not part of the public API.
///
/// Numbers: a token is a number only if the whole token parses (std::from_chars, decimal or
/// decimal exponent notation, an optional leading '+'): "0x3e8", "1.5m" and "1e400xyz" are not
/// numbers. A value beyond the range of double ("1e400") is refused, a value below it (a
/// denormal, "1e-400") reads as the nearest double. "nan" and "inf" (any case, optionally signed)
/// read as NaN, so that readers that drop non-finite points can count them.

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>

namespace intervox::detail {

/// Parses the whole of \p s as a double (see the file comment). \returns false if it is not one.
inline bool parse_double(std::string_view s, double& v) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const char* end = s.data() + s.size();
  const auto [p, ec] = std::from_chars(s.data(), end, v);
  if (ec == std::errc::result_out_of_range) {
    if (p != end) return false;  // trailing garbage after an out-of-range number: "1e400xyz"
    // from_chars leaves v unchanged when out of range: strtod tells overflow from underflow.
    const double r = std::strtod(std::string(s).c_str(), nullptr);
    if (std::isinf(r)) return false;  // beyond the range of double: "1e400"
    v = r;
    return true;
  }
  if (ec == std::errc{} && p == end) return true;
  // from_chars does not accept "nan"/"inf" spellings of every writer; treat them as non-finite.
  std::string lower(s);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == "nan" || lower == "-nan" || lower == "inf" || lower == "-inf" || lower == "infinity" ||
      lower == "-infinity") {
    v = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  return false;
}

/// Parses the whole of \p s as an unsigned decimal integer. \returns false if it is not one or
/// does not fit in 64 bits.
inline bool parse_size(std::string_view s, std::uint64_t& v) {
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc{} && p == s.data() + s.size() && !s.empty();
}

/// \p text made safe to quote in an error message: printable ASCII is kept, every other byte
/// (control characters such as ESC, which a terminal would interpret, DEL and bytes >= 0x80)
/// becomes \xNN, and a backslash becomes "\\" so that the escaping is unambiguous. At most
/// \p max_bytes bytes of \p text are quoted; a longer text ends with "...".
inline std::string quote_bytes(std::string_view text, std::size_t max_bytes = 80) {
  std::string out;
  const bool cut = text.size() > max_bytes;
  if (cut) text = text.substr(0, max_bytes);
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\\') {
      out += "\\\\";
    } else if (c >= 0x20 && c < 0x7F) {
      out += ch;
    } else {
      char buf[5];
      std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned>(c));
      out += buf;
    }
  }
  if (cut) out += "...";
  return out;
}

}  // namespace intervox::detail
