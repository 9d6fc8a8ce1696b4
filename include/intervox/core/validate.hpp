#pragma once
/// \file
/// Parameter validation: the one style of the library.
///
/// The rule: a parameter check binds a ParamCheck to the name of what is checked (the type, or
/// the function, with its namespace: "intervox::BayesParams", "intervox::sim::Material") and calls
/// one of its checks per parameter: finite(), nonnegative(), positive(), at_least(),
/// in_range(), valid_bounds(); a rule none of them states (one parameter against another, a
/// choice from an enumeration) calls fail() with the message. Every check throws InvalidArgument
/// (never anything else) with one message format,
///
///     <where>: <name> must <rule>, got <value>
///
/// e.g. "intervox::GainOptions: max_range must be finite and > 0, got -1" or
/// "intervox::BayesParams: p_hit must lie in (0.5, 1), got 0.4", so that a message always names
/// the type and the parameter. Numbers print with six significant digits ("0.4", "-1", "nan",
/// "inf", "1e-09"). Tests that check a message match the parameter's name, not the wording.
///
/// \code
///   void validate() const {
///     const ParamCheck check("intervox::ArmPlannerParams");
///     check.positive("sphere_radius", sphere_radius);
///     check.nonnegative("sweep_length", sweep_length);
///     check.at_least("candidates", candidates, 1);
///     if (min_elevation > max_elevation) check.fail("need min_elevation <= max_elevation");
///   }
/// \endcode
///
/// Thread safety: a ParamCheck holds a pointer to a string literal; its checks are reentrant.

#include <intervox/core/error.hpp>

#include <cmath>
#include <concepts>
#include <cstdio>
#include <string>
#include <type_traits>

namespace intervox {

/// Which ends of the interval a value may take in ParamCheck::in_range.
enum class RangeEnds {
  Closed,      ///< [lo, hi]
  Open,        ///< (lo, hi)
  OpenClosed,  ///< (lo, hi]
  ClosedOpen,  ///< [lo, hi)
};

namespace detail {
/// A number as the validation messages print it: %g (six significant digits; "nan", "inf").
inline std::string param_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
/// An integer as the validation messages print it: exactly.
template <std::integral I>
std::string param_text(I v) {
  return std::to_string(v);
}
}  // namespace detail

/// The checks of one parameter set (or one function's arguments), bound to its name; see the
/// file comment for the rule and the message format. Every check returns normally when the value
/// passes, and otherwise throws InvalidArgument.
class ParamCheck {
 public:
  /// \param where the checked type or function with its namespace, e.g. "intervox::BayesParams";
  ///        a string that outlives the ParamCheck (a literal)
  explicit constexpr ParamCheck(const char* where) noexcept : where_(where) {}

  /// The name the messages start with.
  constexpr const char* where() const noexcept { return where_; }

  /// Fails with a rule no other check states: throws InvalidArgument("<where>: <what>").
  /// \throws InvalidArgument always.
  [[noreturn]] void fail(const std::string& what) const { throw InvalidArgument(std::string(where_) + ": " + what); }

  /// \throws InvalidArgument unless \p value is finite ("<name> must be finite, got <value>").
  void finite(const char* name, double value) const {
    if (!std::isfinite(value)) fail_value(name, "be finite", value);
  }
  /// \throws InvalidArgument unless \p value is finite and >= 0 ("must be finite and >= 0").
  void nonnegative(const char* name, double value) const {
    if (!(std::isfinite(value) && value >= 0)) fail_value(name, "be finite and >= 0", value);
  }
  /// \throws InvalidArgument unless \p value is finite and > 0 ("must be finite and > 0").
  void positive(const char* name, double value) const {
    if (!(std::isfinite(value) && value > 0)) fail_value(name, "be finite and > 0", value);
  }
  /// \throws InvalidArgument unless \p value is finite and >= \p min ("must be finite and >= min").
  void at_least(const char* name, double value, double min) const {
    if (!(std::isfinite(value) && value >= min)) fail_value(name, "be finite and >= " + detail::param_text(min), value);
  }
  /// An integer: \throws InvalidArgument unless \p value >= \p min ("must be >= min").
  template <std::integral I>
  void at_least(const char* name, I value, std::type_identity_t<I> min) const {
    if (value < min) fail_value(name, "be >= " + detail::param_text(min), value);
  }
  /// \throws InvalidArgument unless \p value lies in the interval from \p lo to \p hi with the
  /// given ends ("must lie in [lo, hi]"; NaN never does).
  void in_range(const char* name, double value, double lo, double hi, RangeEnds ends = RangeEnds::Closed) const {
    const bool lo_open = ends == RangeEnds::Open || ends == RangeEnds::OpenClosed;
    const bool hi_open = ends == RangeEnds::Open || ends == RangeEnds::ClosedOpen;
    const bool ok = (lo_open ? value > lo : value >= lo) && (hi_open ? value < hi : value <= hi);
    if (!ok) {
      fail_value(name,
                 std::string("lie in ") + (lo_open ? "(" : "[") + detail::param_text(lo) + ", " +
                     detail::param_text(hi) + (hi_open ? ")" : "]"),
                 value);
    }
  }
  /// An integer: \throws InvalidArgument unless lo <= \p value <= hi ("must lie in [lo, hi]").
  template <std::integral I>
  void in_range(const char* name, I value, std::type_identity_t<I> lo, std::type_identity_t<I> hi) const {
    if (value < lo || value > hi)
      fail_value(name, "lie in [" + detail::param_text(lo) + ", " + detail::param_text(hi) + "]", value);
  }
  /// A box (anything with `valid()`, e.g. Bounds): \throws InvalidArgument unless it is valid
  /// ("<name> must be finite with min <= max").
  template <class Box>
  requires requires(const Box& b) {
    { b.valid() } -> std::convertible_to<bool>;
  }
  void valid_bounds(const char* name, const Box& box) const {
    if (!box.valid()) fail_invalid_box(name);
  }

 private:
  // Out of line: GCC 12 at -O1 (the TSan build) reports a false -Warray-bounds in the string
  // concatenation once it is inlined into a caller (GridGeometry::key_box).
  [[noreturn]] [[gnu::noinline]] void fail_invalid_box(const char* name) const {
    std::string what(name);
    what += " must be finite with min <= max";
    fail(what);
  }
  template <class T>
  [[noreturn]] void fail_value(const char* name, const std::string& rule, T value) const {
    fail(std::string(name) + " must " + rule + ", got " + detail::param_text(value));
  }

  const char* where_;
};

}  // namespace intervox
