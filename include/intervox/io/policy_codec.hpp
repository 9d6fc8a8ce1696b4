#pragma once
/// \file
/// The customisation point of the grid file format (io/grid_file.hpp): how an update policy's
/// parameters and cells are stored, and the concept that checks it. Intervox's own policies have
/// their codecs in io/codec/ (one header per policy, named as the policy's header); a policy of
/// your own gets one by a specialisation of PolicyCodec in your code, with no edit in io/.
///
/// Thread safety: declarations only.

#include <intervox/io/detail/binary.hpp>
#include <intervox/update/concepts.hpp>

#include <concepts>
#include <cstddef>
#include <span>
#include <vector>

namespace intervox {

/// Customisation point: how an update policy's parameters and cells are stored in a grid file.
/// Specialise it for a policy of your own (io/codec/ holds Intervox's). Required members, checked
/// by GridFilePolicy:
///  - `static std::vector<double> encode(const U&)`: every parameter as a double;
///  - `static U decode(std::span<const double>)`: the inverse; may throw InvalidArgument;
///  - `static constexpr std::size_t kCellBytes`, `static void write_cell(detail::ByteWriter&, const Cell&)`,
///    `static Cell read_cell(detail::ByteReader&)` (exactly kCellBytes bytes each);
///  - `static bool valid_cell(const Cell&)`: false for a value the policy could never produce.
/// \tparam U the update policy
template <class U>
struct PolicyCodec;

/// An update policy whose grids can be saved and loaded: PolicyCodec<U> is specialised with the
/// members above. save_grid and load_grid require it, so a grid of a policy without a codec is
/// rejected with one line naming this concept.
/// \tparam U the update policy
template <class U>
concept GridFilePolicy = UpdatePolicy<U> && requires(const U& u, std::span<const double> params, detail::ByteWriter& w,
                                                     detail::ByteReader& r, const typename U::Cell& c) {
  { PolicyCodec<U>::encode(u) } -> std::same_as<std::vector<double>>;
  { PolicyCodec<U>::decode(params) } -> std::same_as<U>;
  { PolicyCodec<U>::kCellBytes } -> std::convertible_to<std::size_t>;
  PolicyCodec<U>::write_cell(w, c);
  { PolicyCodec<U>::read_cell(r) } -> std::same_as<typename U::Cell>;
  { PolicyCodec<U>::valid_cell(c) } -> std::same_as<bool>;
};

}  // namespace intervox
