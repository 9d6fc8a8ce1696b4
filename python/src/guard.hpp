#pragma once
/// \file
/// The busy guard of the Python module: a grid, a ScanInserter, a planner or an Episode used by
/// two Python threads at once (the GIL is released while C++ works) raises RuntimeError instead
/// of corrupting memory.
///
/// Rules, per object (keyed by the address of its C++ object): any number of calls that take it
/// as `const T&` (queries) may run together; a call that takes it as `T&` (insertion, update,
/// clear, planning, episodes) needs it alone. A call that finds the object in use by another
/// thread in a conflicting way raises RuntimeError "<Type> is in use by another thread" before
/// touching it. The thread that holds an object exclusively may use it again (a Python callback
/// of an Episode may query its grid).
///
/// Which types are guarded: kGuardedName<T> (common.hpp) is set for them.
/// Implemented once: guarded(f) wraps any function or member function pointer so that every
/// argument of a guarded type (kGuardedName<T> set) is held for the call; guarded_class<T> is a
/// py::class_<T> whose def / def_static / def_property_readonly wrap every
/// function they are given, so that no method of a guarded class can forget the guard.

#include "common.hpp"

#include <cstddef>
#include <memory>
#include <optional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <unordered_map>
#include <utility>

namespace intervox::python {

namespace guard_detail {

/// Which objects are in use, and how: one table for the module, behind one mutex (held only to
/// look up and update an entry, never while C++ or Python works).
class Registry {
 public:
  static Registry& instance() {
    static Registry r;
    return r;
  }
  /// \throws std::runtime_error (RuntimeError) if \p p is in use by another thread in a way that
  ///         conflicts with this use.
  void acquire(const void* p, bool exclusive, const char* name) {
    const std::thread::id me = std::this_thread::get_id();
    std::lock_guard<std::mutex> lock(mutex_);
    State& s = states_[p];
    const bool mine = s.writes > 0 && s.writer == me;
    if (exclusive) {
      if ((s.writes > 0 && !mine) || (s.writes == 0 && s.reads > 0)) refuse(p, s, name);
      s.writer = me;
      ++s.writes;
    } else {
      if (s.writes > 0 && !mine) refuse(p, s, name);
      ++s.reads;
    }
  }
  void release(const void* p, bool exclusive) noexcept {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = states_.find(p);
    if (it == states_.end()) return;
    State& s = it->second;
    if (exclusive)
      --s.writes;
    else
      --s.reads;
    if (s.writes == 0 && s.reads == 0) states_.erase(it);
  }

 private:
  struct State {
    std::thread::id writer;
    unsigned writes = 0;
    unsigned reads = 0;
  };
  [[noreturn]] void refuse(const void* p, const State& s, const char* name) {
    if (s.writes == 0 && s.reads == 0) states_.erase(p);
    throw std::runtime_error(std::string(name) +
                             " is in use by another thread (a grid, inserter, planner or episode may be shared between "
                             "threads for concurrent queries only; give each writing thread its own object)");
  }
  std::mutex mutex_;
  std::unordered_map<const void*, State> states_;
};

/// Holds one object for the lifetime of the guard.
class Hold {
 public:
  Hold(const void* p, bool exclusive, const char* name) : p_(p), exclusive_(exclusive) {
    Registry::instance().acquire(p, exclusive, name);
  }
  ~Hold() { Registry::instance().release(p_, exclusive_); }
  Hold(const Hold&) = delete;
  Hold& operator=(const Hold&) = delete;

 private:
  const void* p_;
  bool exclusive_;
};

/// True if an argument of type A (as the bound function declares it) is a guarded object.
template <class A>
inline constexpr bool kHeld = std::is_lvalue_reference_v<A>&& kGuardedName<std::remove_cvref_t<A>> != nullptr;

/// Holds every guarded argument among \p args, in order (released in reverse order).
template <class... Args>
class HoldAll {
 public:
  explicit HoldAll(Args&... args) : holds_{make<Args>(args)...} {}

 private:
  template <class A, class T>
  static std::optional<Hold> make(T& arg) {
    if constexpr (kHeld<A>)
      return std::optional<Hold>(std::in_place, static_cast<const void*>(std::addressof(arg)),
                                 !std::is_const_v<std::remove_reference_t<A>>, kGuardedName<std::remove_cvref_t<A>>);
    else
      return std::nullopt;
  }
  std::optional<Hold> holds_[sizeof...(Args) + 1];  // (+ 1: no zero-length array)
};

template <class R, class... Args, class F>
auto wrap(F f) {
  if constexpr ((kHeld<Args> || ...)) {
    return [f = std::move(f)](Args... args) -> R {
      const HoldAll<Args...> hold(args...);
      return f(std::forward<Args>(args)...);
    };
  } else {
    return f;
  }
}

/// The signature of a callable: a function pointer, a member function pointer (the object
/// first) or an object with one operator() (a non-generic lambda).
template <class F, class = void>
struct Sig;
template <class R, class... A>
struct Sig<R (*)(A...)> {
  template <class F>
  static auto guard(F f) {
    return wrap<R, A...>(std::move(f));
  }
};
template <class R, class... A>
struct Sig<R (*)(A...) noexcept> : Sig<R (*)(A...)> {};
template <class R, class C, class... A>
struct Sig<R (C::*)(A...)> {
  template <class F>
  static auto guard(F f) {
    return wrap<R, C&, A...>([f](C& c, A... a) -> R { return (c.*f)(std::forward<A>(a)...); });
  }
};
template <class R, class C, class... A>
struct Sig<R (C::*)(A...) const> {
  template <class F>
  static auto guard(F f) {
    return wrap<R, const C&, A...>([f](const C& c, A... a) -> R { return (c.*f)(std::forward<A>(a)...); });
  }
};
template <class R, class C, class... A>
struct Sig<R (C::*)(A...) noexcept> : Sig<R (C::*)(A...)> {};
template <class R, class C, class... A>
struct Sig<R (C::*)(A...) const noexcept> : Sig<R (C::*)(A...) const> {};
/// A lambda: its operator()'s argument list, called on a copy of the lambda.
template <class L, class R, class... A>
struct LambdaSig {
  static auto guard(L f) { return wrap<R, A...>(std::move(f)); }
};
template <class L, class M>
struct OperatorSig;
template <class L, class R, class C, class... A>
struct OperatorSig<L, R (C::*)(A...) const> : LambdaSig<L, R, A...> {};
template <class L, class R, class C, class... A>
struct OperatorSig<L, R (C::*)(A...)> : LambdaSig<L, R, A...> {};
template <class L, class R, class C, class... A>
struct OperatorSig<L, R (C::*)(A...) const noexcept> : LambdaSig<L, R, A...> {};
template <class L, class R, class C, class... A>
struct OperatorSig<L, R (C::*)(A...) noexcept> : LambdaSig<L, R, A...> {};
template <class F>
struct Sig<F, std::void_t<decltype(&F::operator())>> {
  static auto guard(F f) { return OperatorSig<F, decltype(&F::operator())>::guard(std::move(f)); }
};

}  // namespace guard_detail

/// \p f, holding each of its guarded arguments for the call (see the file comment).
template <class F>
auto guarded(F&& f) {
  using D = std::decay_t<F>;
  return guard_detail::Sig<D>::guard(D(std::forward<F>(f)));
}

/// Holds the objects of an Episode (its grid and planner), which its methods use without taking
/// them as arguments: exclusive, as an argument `T&` would be.
using ObjectHold = guard_detail::Hold;

/// A py::class_<T> whose def, def_static and def_property_readonly wrap every
/// function in guarded(): every method of the class holds its guarded arguments (self first).
template <class T>
class guarded_class : public py::class_<T> {
  using Base = py::class_<T>;

 public:
  using Base::Base;
  explicit guarded_class(Base c) : Base(std::move(c)) {}

  template <class F, class... Extra>
  guarded_class& def(const char* name, F&& f, const Extra&... extra) {
    Base::def(name, guarded(std::forward<F>(f)), extra...);
    return *this;
  }
  /// Constructors (py::init): nothing to hold yet; the arguments are held by the factory's
  /// own wrapping where it takes guarded objects (see guarded_init).
  template <class I, class... Extra>
  requires(!std::is_convertible_v<I, const char*>) guarded_class& def(I&& init, const Extra&... extra) {
    Base::def(std::forward<I>(init), extra...);
    return *this;
  }
  template <class F, class... Extra>
  guarded_class& def_static(const char* name, F&& f, const Extra&... extra) {
    Base::def_static(name, guarded(std::forward<F>(f)), extra...);
    return *this;
  }
  template <class G, class... Extra>
  guarded_class& def_property_readonly(const char* name, G&& getter, const Extra&... extra) {
    Base::def_property_readonly(name, py::cpp_function(guarded(std::forward<G>(getter))), extra...);
    return *this;
  }
  template <class G, class... Extra>
  guarded_class& def_property_readonly_static(const char* name, G&& getter, const Extra&... extra) {
    Base::def_property_readonly_static(name, std::forward<G>(getter), extra...);
    return *this;
  }
  /// Not supported (no guarded class has a writable property): deleted so that none is added
  /// without the guard.
  template <class... A>
  guarded_class& def_property(A&&...) = delete;
  template <class... A>
  guarded_class& def_readwrite(A&&...) = delete;
};

/// The registered Python class of grid type G (created by bind_grids, extended by the others),
/// with the guard on every method added.
template <class G>
guarded_class<G> grid_class(py::module_& m) {
  return guarded_class<G>(py::reinterpret_borrow<py::class_<G>>(m.attr(kGridName<G>)));
}

}  // namespace intervox::python
