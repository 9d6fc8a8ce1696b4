#pragma once
/// \file
/// Exception types. Every exception Intervox throws derives from intervox::Error.
/// Parameters are checked one way, with ParamCheck (core/validate.hpp), which throws InvalidArgument.
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

}  // namespace intervox
