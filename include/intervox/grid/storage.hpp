#pragma once
/// \file
/// The Storage concept: where a grid keeps its cells.
/// Thread safety: containers allow concurrent const access; writers need exclusive access.

#include <intervox/core/key.hpp>

#include <concepts>
#include <cstddef>
#include <optional>

namespace intervox {

/// Requirements on the container a storage tag produces for a cell type.
///
/// With `s` a container and `k` a Key:
///  - construction from `(Cell unobserved, std::optional<KeyBox> box)`; a bounded container
///    requires the box;
///  - `s.find(k)`: pointer to the cell of k, or nullptr if it has no storage (never allocates);
///  - `s.touch(k)`: pointer to the cell of k, allocating it (initialised to `unobserved`) if
///    needed; nullptr if k lies outside the box or the key range;
///  - `s.for_each(f)`: calls `f(const Key&, Cell&)` for every allocated cell, in a
///    deterministic order (also as const, with `const Cell&`);
///  - `s.for_each_in(q, f)`: the same for the allocated cells whose keys lie in the KeyBox `q`,
///    visiting only the storage that overlaps it;
///  - `s.allocated()`, `s.memory_bytes()`, `s.clear()`, `s.box()`.
/// \tparam C the container type; \tparam Cell its cell type
template <class C, class Cell>
concept StorageContainer = std::constructible_from<C, Cell, std::optional<KeyBox>> &&
    requires(C& s, const C& cs, const Key& k) {
  { s.find(k) } -> std::same_as<Cell*>;
  { cs.find(k) } -> std::same_as<const Cell*>;
  { s.touch(k) } -> std::same_as<Cell*>;
  { cs.allocated() } -> std::same_as<std::size_t>;
  { cs.memory_bytes() } -> std::same_as<std::size_t>;
  { cs.box() } -> std::same_as<const std::optional<KeyBox>&>;
  s.clear();
};

/// A storage tag names a container template and whether it needs bounds.
///
/// Required: `S::template Container<Cell>` satisfying StorageContainer, `S::kBounded`, `S::kName`.
/// \tparam S the candidate tag
template <class S>
concept Storage = requires {
  { S::kBounded } -> std::convertible_to<bool>;
  { S::kName } -> std::convertible_to<std::string_view>;
}
&&StorageContainer<typename S::template Container<float>, float>;

}  // namespace intervox
