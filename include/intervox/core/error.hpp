#pragma once
/// \file
/// Exception types. Every exception Intervox throws derives from intervox::Error.
/// Thread safety: exception objects, as std::runtime_error.

#include <stdexcept>
#include <string>

namespace intervox {

/// Base of every exception thrown by Intervox.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A parameter or argument is invalid (NaN, out of its documented range, inconsistent).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// A point or key lies outside what the grid can represent or what a bounded grid covers.
class OutOfRange : public Error {
 public:
  using Error::Error;
};

/// Reading or writing a file failed, or a file is corrupt.
class IoError : public Error {
 public:
  using Error::Error;
};

/// The failure of a parameter check, bound to the name of what is checked:
/// `const ParamFailure fail("intervox::BayesParams"); ... fail("p_hit must ...");` throws
/// InvalidArgument("intervox::BayesParams: p_hit must ..."). Never returns (so the compiler
/// knows every path after a failed check ends there).
class ParamFailure {
 public:
  explicit constexpr ParamFailure(const char* where) noexcept : where_(where) {}
  /// \throws InvalidArgument always.
  [[noreturn]] void operator()(const std::string& what) const {
    throw InvalidArgument(std::string(where_) + ": " + what);
  }

 private:
  const char* where_;
};

}  // namespace intervox
