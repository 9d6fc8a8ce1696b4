#pragma once
// Command lines of the example programs (CLI11, Debian libcli11-dev): one main wrapper that parses,
// reports a wrong command line as "program: error: ..." with exit code 2, and runs the program under
// guarded_main (errors while running: exit code 1), and checks for numbers that CLI11 alone lets
// through ("-1" read into an unsigned 64-bit option wraps to 2^64-1; NaN passes CLI::Range).
#include "guarded_main.hpp"

#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

namespace examples {

/// A CLI11 check: a whole decimal number within [min, max] of the integer type T. No sign on
/// unsigned types, no fraction, exponent, hexadecimal or surrounding text, no wrap-around.
template <class T>
CLI::Validator integer_in(T min = std::numeric_limits<T>::min(), T max = std::numeric_limits<T>::max()) {
  static_assert(std::is_integral_v<T>);
  const std::string range = "[" + std::to_string(min) + " - " + std::to_string(max) + "]";
  return CLI::Validator(
      [min, max, range](std::string& text) -> std::string {
        T value{};
        const char* end = text.data() + text.size();
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (text.empty() || error != std::errc{} || stop != end || value < min || value > max) {
          return "expected a whole number in " + range + ", got '" + text + "'";
        }
        return {};
      },
      // Shown in --help after the type (UINT, INT): nothing for the whole range of the type.
      max != std::numeric_limits<T>::max()   ? "INT in " + range
      : min == std::numeric_limits<T>::min() ? std::string()
      : min == 0                             ? "NONNEGATIVE"
                                             : ">= " + std::to_string(min));
}

/// A validator accepting exactly the names in \p names (any range of string-like values, e.g.
/// intervox::sim::kMaterialNames).
template <class Range>
CLI::Validator one_of(const Range& names) {
  std::vector<std::string> v;
  for (const auto& n : names) v.emplace_back(n);
  return CLI::IsMember(v);
}

/// A CLI11 check: a finite decimal number within [min, max] (NaN and infinities are rejected).
inline CLI::Validator number_in(double min = std::numeric_limits<double>::lowest(),
                                double max = std::numeric_limits<double>::max()) {
  std::ostringstream bounds;
  bounds << "[" << min << " - " << max << "]";
  const bool whole_range = min == std::numeric_limits<double>::lowest() && max == std::numeric_limits<double>::max();
  const std::string range = whole_range ? "finite" : bounds.str();
  return CLI::Validator(
      [min, max, range](std::string& text) -> std::string {
        double value = 0;
        const char* end = text.data() + text.size();
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (text.empty() || error != std::errc{} || stop != end || !std::isfinite(value) || value < min ||
            value > max) {
          return "expected a finite number " + (range == "finite" ? std::string() : "in " + range + ", ") + "got '" +
                 text + "'";
        }
        return {};
      },
      range == "finite" ? "FINITE" : "FLOAT in " + range);
}

/// Parses the command line into `app`, then returns `body()` run under guarded_main. A wrong
/// command line prints "program: error: ..." and a pointer to --help on stderr and returns
/// kUsageError; --help prints the help on stdout and returns 0.
template <class Body>
int cli_main(std::string_view program, CLI::App& app, int argc, char** argv, Body&& body) noexcept {
  return guarded_main(program, [&]() -> int {
    app.failure_message([name = std::string(program)](const CLI::App*, const CLI::Error& e) {
      return name + ": error: " + e.what() + "\nRun with --help for more information.\n";
    });
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : kUsageError;
    }
    return body();
  });
}

}  // namespace examples
