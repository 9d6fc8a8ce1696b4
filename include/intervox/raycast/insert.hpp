#pragma once
/// \file
/// Ray insertion: point clouds, depth images, beams and single rays into any VoxelGrid, with the
/// semantics of OctoMap's `insertPointCloud` (exact traversal, per-scan de-duplication, a hit
/// wins over a miss), exact for any number of scans and any number of threads.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/types.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/detail/box_marks.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <iterator>
#include <limits>
#include <ranges>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace intervox {

/// Options of ray insertion.
struct InsertOptions {
  /// Rays longer than this are cut at this distance from their origin and carry misses only
  /// (no hit); beams without a return are free up to it. Negative or +inf: no max range (then
  /// beams without a return are skipped).
  double max_range = -1.0;
  /// Points closer than this to their origin are skipped (counted in skipped_min_range).
  double min_range = 0.0;
  /// Threads for traversal and update: 1 (default) runs on the calling thread, 0 uses
  /// std::thread::hardware_concurrency(). The result is identical for every value.
  unsigned threads = 1;

  /// True if a finite, non-negative max range is set.
  bool has_max_range() const noexcept { return max_range >= 0.0 && std::isfinite(max_range); }

  /// \throws InvalidArgument if max_range is NaN, min_range is NaN, negative or infinite, or
  ///         min_range exceeds a set max_range.
  void validate() const {
    if (std::isnan(max_range)) throw InvalidArgument("intervox::InsertOptions: max_range is NaN");
    if (!(min_range >= 0.0 && std::isfinite(min_range)))
      throw InvalidArgument("intervox::InsertOptions: min_range must be finite and >= 0, got " +
                            std::to_string(min_range));
    if (has_max_range() && min_range > max_range)
      throw InvalidArgument("intervox::InsertOptions: min_range " + std::to_string(min_range) +
                            " exceeds max_range " + std::to_string(max_range));
  }
};

/// What one insertion did. Every input ray is counted exactly once: either in `rays` or in one
/// of the `skipped_*` counters.
struct InsertStats {
  std::uint64_t rays = 0;         ///< rays traversed (with a hit, or cut at max range)
  std::uint64_t truncated = 0;    ///< of those, rays cut at max range (misses only)
  std::uint64_t voxel_steps = 0;  ///< voxels enumerated by the traversals, before de-duplication
  std::uint64_t hits = 0;         ///< voxels updated with a hit (after de-duplication)
  std::uint64_t misses = 0;       ///< voxels updated with a miss (after de-duplication)
  std::uint64_t outside_bounds = 0;  ///< voxel updates dropped: outside a bounded grid's box

  std::uint64_t skipped_invalid = 0;       ///< NaN/Inf point or origin, invalid depth pixel
  std::uint64_t skipped_zero_length = 0;   ///< point equal to its origin
  std::uint64_t skipped_min_range = 0;     ///< point closer than min_range
  std::uint64_t skipped_key_range = 0;     ///< origin or (cut) end outside the key range
  std::uint64_t skipped_no_max_range = 0;  ///< beam without a return, but no max range set

  /// Input rays not traversed, for any reason.
  std::uint64_t skipped() const noexcept {
    return skipped_invalid + skipped_zero_length + skipped_min_range + skipped_key_range + skipped_no_max_range;
  }
  InsertStats& operator+=(const InsertStats& o) noexcept {
    rays += o.rays;
    truncated += o.truncated;
    voxel_steps += o.voxel_steps;
    hits += o.hits;
    misses += o.misses;
    outside_bounds += o.outside_bounds;
    skipped_invalid += o.skipped_invalid;
    skipped_zero_length += o.skipped_zero_length;
    skipped_min_range += o.skipped_min_range;
    skipped_key_range += o.skipped_key_range;
    skipped_no_max_range += o.skipped_no_max_range;
    return *this;
  }
  friend bool operator==(const InsertStats&, const InsertStats&) = default;
};

namespace detail {

/// One input ray before validation. `hit == false`: no return; `end` is any point along the
/// beam's direction.
struct RayInput {
  Point3 origin;
  Point3 end;
  bool hit;
};

/// The set of voxels one scan touches, as 8^3-block bitmaps in an open-addressing table keyed
/// by the packed block coordinate. Cleared exactly between scans (no stamps, no wrap-around).
class ScanMarks {
 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // never a packed id (63 bits)

  ScanMarks() { reset_table(256); }

  /// Packs the block coordinate of a key, 21 bits per axis (keys are within +-2^23).
  static std::uint64_t block_id(const Key& k) noexcept {
    auto c = [](std::int32_t v) {
      return static_cast<std::uint64_t>(static_cast<std::uint32_t>((v >> 3) + (1 << 20)) & 0x1FFFFFu);
    };
    return c(k.x) | (c(k.y) << 21) | (c(k.z) << 42);
  }
  /// Minimum key of the block with packed id \p id.
  static Key block_base(std::uint64_t id) noexcept {
    auto c = [](std::uint64_t v) {
      return static_cast<std::int32_t>(static_cast<std::int64_t>(v & 0x1FFFFFu) - (1 << 20)) * 8;
    };
    return Key{c(id), c(id >> 21), c(id >> 42)};
  }

  /// The marks of block \p id, created (zeroed) if new. The pointer stays valid until the next
  /// call that creates a block, or clear().
  BlockMarks* get(std::uint64_t id) {
    std::size_t i = slot(id);
    for (;; i = (i + 1) & mask_) {
      const Slot& s = table_[i];
      if (s.id == id) return &marks_[s.index];
      if (s.id == kEmpty) break;
    }
    if ((ids_.size() + 1) * 2 > table_.size()) {
      grow();
      i = slot(id);
      while (table_[i].id != kEmpty) i = (i + 1) & mask_;
    }
    table_[i] = Slot{id, static_cast<std::uint32_t>(ids_.size())};
    ids_.push_back(id);
    marks_.push_back(BlockMarks{});
    return &marks_.back();
  }

  /// Forgets every mark; keeps the memory.
  void clear() noexcept {
    for (std::uint64_t id : ids_) {
      std::size_t i = slot(id);
      while (table_[i].id != id) i = (i + 1) & mask_;
      table_[i].id = kEmpty;
    }
    // Removing entries from a linear-probing table may leave holes in other chains, but every
    // entry is removed here, so the table ends fully empty.
    ids_.clear();
    marks_.clear();
  }

  /// Adds every mark of \p o (set union).
  void merge(const ScanMarks& o) {
    for (std::size_t j = 0; j < o.ids_.size(); ++j) {
      BlockMarks* m = get(o.ids_[j]);
      const BlockMarks& s = o.marks_[j];
      for (int w = 0; w < 8; ++w) {
        m->miss[w] |= s.miss[w];
        m->hit[w] |= s.hit[w];
      }
    }
  }

  std::size_t size() const noexcept { return ids_.size(); }
  std::uint64_t id(std::size_t j) const noexcept { return ids_[j]; }
  const BlockMarks& marks(std::size_t j) const noexcept { return marks_[j]; }
  std::size_t memory_bytes() const noexcept {
    return table_.capacity() * sizeof(Slot) + ids_.capacity() * sizeof(std::uint64_t) +
           marks_.capacity() * sizeof(BlockMarks);
  }

 private:
  struct Slot {
    std::uint64_t id;
    std::uint32_t index;
  };
  std::size_t slot(std::uint64_t id) const noexcept {
    return static_cast<std::size_t>((id * 0x9E3779B97F4A7C15ULL) >> shift_);
  }
  void reset_table(std::size_t n) {
    table_.assign(n, Slot{kEmpty, 0});
    mask_ = n - 1;
    shift_ = 64 - std::countr_zero(n);
  }
  void grow() {
    reset_table(table_.size() * 2);
    for (std::size_t j = 0; j < ids_.size(); ++j) {
      std::size_t i = slot(ids_[j]);
      while (table_[i].id != kEmpty) i = (i + 1) & mask_;
      table_[i] = Slot{ids_[j], static_cast<std::uint32_t>(j)};
    }
  }

  std::vector<Slot> table_;
  std::vector<std::uint64_t> ids_;
  std::vector<BlockMarks> marks_;
  std::size_t mask_ = 0;
  int shift_ = 64;
};

/// Marks rays into a ScanMarks, caching the current block.
class RayMarker {
 public:
  explicit RayMarker(ScanMarks& marks) : marks_(&marks) {}

  /// Traverses one prepared segment: misses from the first voxel up to, not including, the last;
  /// a hit in the last if \p hit. Returns the number of voxels enumerated.
  std::uint64_t mark(const Point3& v0, const Point3& v1, const Key& k0, const Key& k1, bool hit) {
    const SegmentDda dda(v0, v1, k0, k1);
    const std::uint64_t n = dda.remaining;
    if (n != 0) {
      // The same walk as SegmentDda::advance(), written branch-free in registers: the axis
      // choice of a ray is unpredictable, so a branch there costs a misprediction per step.
      constexpr double inf = std::numeric_limits<double>::infinity();
      std::int32_t kx = k0.x, ky = k0.y, kz = k0.z;
      const std::int32_t sx = dda.step[0], sy = dda.step[1], sz = dda.step[2];
      const std::int32_t ex = k1.x, ey = k1.y, ez = k1.z;
      double tx = dda.t_max[0], ty = dda.t_max[1], tz = dda.t_max[2];
      const double dx = dda.t_delta[0], dy = dda.t_delta[1], dz = dda.t_delta[2];
      std::uint64_t id = ScanMarks::block_id(k0);
      // Bits of the current 64-bit word (one z-slice of a block) gather in a register and are
      // written when the walk leaves that word: no store-to-load chain through memory per step.
      std::uint64_t* word = &block_of(id)->miss[kz & 7];
      std::uint64_t acc = 0;
      for (std::uint64_t i = n;;) {
        acc |= std::uint64_t{1} << ((kx & 7) | ((ky & 7) << 3));
        if (--i == 0) break;
        // Ties step the higher axis (OctoMap's rule); an axis that reached its end key never
        // steps again (its t becomes inf), so the walk ends exactly in k1.
        const bool xy = tx < ty;
        const double m = xy ? tx : ty;
        const bool selz = !(m < tz);
        const bool selx = xy && !selz;
        const bool sely = !xy && !selz;
        kx += selx ? sx : 0;
        ky += sely ? sy : 0;
        kz += selz ? sz : 0;
        tx = selx ? (kx == ex ? inf : tx + dx) : tx;
        ty = sely ? (ky == ey ? inf : ty + dy) : ty;
        tz = selz ? (kz == ez ? inf : tz + dz) : tz;
        const std::uint64_t next = ScanMarks::block_id(Key{kx, ky, kz});
        if (selz || next != id) {
          *word |= acc;
          acc = 0;
          id = next;
          word = &block_of(id)->miss[kz & 7];
        }
      }
      *word |= acc;
    }
    if (hit) {  // the walk ends exactly in k1 (SegmentDda)
      const Key& k = k1;
      block_of(ScanMarks::block_id(k))->hit[k.z & 7] |= std::uint64_t{1} << ((k.x & 7) | ((k.y & 7) << 3));
    }
    return n + (hit ? 1 : 0);
  }

 private:
  BlockMarks* block_of(std::uint64_t id) {
    if (id != last_id_) {
      last_ = marks_->get(id);
      last_id_ = id;
    }
    return last_;
  }

  ScanMarks* marks_;
  std::uint64_t last_id_ = ScanMarks::kEmpty;
  BlockMarks* last_ = nullptr;
};

/// One input ray that passed prepare_ray(): its segment in voxel coordinates and keys.
struct PreparedRay {
  Point3 v0, v1;
  Key k0, k1;
  bool hit;

  /// The voxels its walk enumerates (the work it takes): the key distance plus one.
  std::uint64_t cost() const noexcept {
    std::uint64_t n = 1;
    for (int a = 0; a < 3; ++a) n += static_cast<std::uint64_t>(std::abs(std::int64_t{k1[a]} - k0[a]));
    return n;
  }
};

/// A position in a list of prepared-ray lists taken as one sequence (list, index).
struct RayPos {
  std::size_t list = 0, index = 0;
  friend bool operator==(const RayPos&, const RayPos&) = default;
};

/// Hands out the prepared rays from \p begin up to \p end of the lists, in order.
class RayCursor {
 public:
  RayCursor(const std::vector<std::vector<PreparedRay>>& lists, RayPos begin, RayPos end) noexcept
      : lists_(&lists), at_(begin), end_(end) {}
  /// The next ray, or nullptr after the last.
  const PreparedRay* next() noexcept {
    for (;;) {
      if (at_ == end_) return nullptr;
      const auto& l = (*lists_)[at_.list];
      if (at_.index < l.size()) return &l[at_.index++];
      ++at_.list;
      at_.index = 0;
    }
  }

 private:
  const std::vector<std::vector<PreparedRay>>* lists_;
  RayPos at_, end_;
};

/// Splits the first \p n lists of prepared rays, taken as one sequence, into \p n runs of
/// about equal cost (PreparedRay::cost()), given each list's total \p cost: run t is
/// [bounds[t], bounds[t + 1]), so that threads get equal work whatever the scan's layout (in an
/// image, rows that see the near floor and rows that see far walls differ several times in cost).
inline std::vector<RayPos> balanced_runs(const std::vector<std::vector<PreparedRay>>& lists,
                                         const std::vector<std::uint64_t>& cost, unsigned n) {
  std::vector<RayPos> bounds(n + 1);
  bounds[n] = RayPos{n, 0};
  std::uint64_t total = 0;
  for (unsigned t = 0; t < n; ++t) total += cost[t];
  std::size_t list = 0;
  std::uint64_t before = 0;  // cost of the lists before `list`
  for (unsigned t = 1; t < n; ++t) {
    const std::uint64_t target = total * t / n;
    while (list < n && before + cost[list] <= target) before += cost[list++];
    if (list == n) {
      bounds[t] = RayPos{n, 0};
      continue;
    }
    std::uint64_t acc = before;
    std::size_t i = 0;
    const auto& l = lists[list];
    while (i < l.size() && acc < target) acc += l[i++].cost();
    bounds[t] = RayPos{list, i};
  }
  return bounds;
}

/// Checks one input ray against the options; on success fills the segment to traverse.
inline bool prepare_ray(const GridGeometry& g, const InsertOptions& o, const RayInput& r, Point3& v0,
                        Point3& v1, Key& k0, Key& k1, bool& hit, InsertStats& st) noexcept {
  if (!is_finite(r.origin) || !is_finite(r.end)) {
    ++st.skipped_invalid;
    return false;
  }
  const Point3 d = r.end - r.origin;
  const double len = d.norm();
  if (len == 0.0) {
    ++st.skipped_zero_length;
    return false;
  }
  if (!std::isfinite(len)) {  // coordinates near the double limit: far outside the key range
    ++st.skipped_key_range;
    return false;
  }
  Point3 end = r.end;
  hit = r.hit;
  bool cut = false;
  if (hit) {
    if (len < o.min_range) {
      ++st.skipped_min_range;
      return false;
    }
    if (o.has_max_range() && len > o.max_range) {
      end = r.origin + d * (o.max_range / len);
      hit = false;
      cut = true;
    }
  } else {
    if (!o.has_max_range()) {
      ++st.skipped_no_max_range;
      return false;
    }
    end = r.origin + d * (o.max_range / len);
    cut = true;
  }
  if (!voxel_of(g, r.origin, v0, k0) || !voxel_of(g, end, v1, k1)) {
    ++st.skipped_key_range;
    return false;
  }
  ++st.rays;
  if (cut) ++st.truncated;
  return true;
}

/// Test access to ScanInserter's internals (forces the block-hash marks).
struct ScanInserterAccess {
  template <class I>
  static void force_hash(I& inserter, bool on) noexcept {
    inserter.force_hash_ = on;
  }
  /// Sets the largest scan whose prepared rays are kept between the two passes, and the chunk
  /// of rays prepared again at a time in larger scans.
  template <class I>
  static void set_max_kept_rays(I& inserter, std::size_t n, std::size_t chunk) noexcept {
    inserter.max_kept_rays_ = n;
    inserter.chunk_rays_ = chunk;
  }
  /// Chooses the marking walk (detail::walk_rays()); all give the same result.
  template <class I>
  static void set_walk(I& inserter, WalkKind walk) noexcept {
    inserter.walk_ = walk;
  }
};

/// True for containers laid out in 8^3 blocks exactly as ScanMarks (SparseBlocks).
template <class C>
concept BlockContainer = requires(C& c, const Key& k) {
  { c.touch_block(k) };
  { C::cell_index(k) } -> std::convertible_to<std::size_t>;
} && (C::kBlockSize == 8);

}  // namespace detail

/// A reusable inserter: keeps its scratch buffers (the per-scan voxel marks, one set per
/// thread) across scans, so repeated insertion allocates nothing once warmed up. Scratch: per
/// thread two bitmaps over the scan's key box (at most 32 MiB; larger scans use a block hash),
/// and the prepared rays of scans of up to 2^20 rays (80 bytes each; larger scans prepare each
/// ray twice instead); scratch_bytes() reports the total.
///
/// Semantics (those of OctoMap's `insertPointCloud(cloud, origin, maxrange)`):
///  - each ray is traversed exactly (traverse()) from the voxel of its origin to the voxel of its
///    end; every voxel on the way gets a miss, the end voxel a hit and no miss. If origin and end
///    share a voxel, that voxel only gets the hit;
///  - a point farther than max_range gives a ray cut at max_range with misses only; as in
///    OctoMap, the voxel containing the cut end is not updated. A beam without a return (depth
///    +inf, Beam::hit == false) is free up to max_range in the same way;
///  - per scan (one call) each voxel is updated at most once, and a hit wins over a miss. The
///    marks are cleared exactly after each scan, so this holds for any number of scans;
///  - bad input is skipped and counted, never thrown: NaN/Inf points or origins, points equal
///    to their origin, points closer than min_range, origins or (cut) ends outside the key range.
///    A ray therefore never exceeds the key range (at most 3 * 2^24 voxels); with a max range it
///    is at most about 1.8 * max_range / resolution voxels;
///  - on a bounded grid, updates outside its box are dropped and counted (outside_bounds).
///
/// Determinism: the updated voxels, their values and the grid's block allocation order are the
/// same for every thread count.
///
/// Thread safety: one inserter per thread; the grid needs exclusive access during a call.
class ScanInserter {
 public:
  /// \throws InvalidArgument for invalid options (InsertOptions::validate()).
  explicit ScanInserter(const InsertOptions& options = {}) { set_options(options); }

  const InsertOptions& options() const noexcept { return options_; }
  /// \throws InvalidArgument for invalid options.
  void set_options(const InsertOptions& options) {
    options.validate();
    options_ = options;
  }

  /// Inserts a point cloud seen from \p origin.
  /// \tparam G a VoxelGrid; \tparam O a PointLike origin
  /// \tparam R a random-access sized range of PointLike points (std::vector<Eigen::Vector3f>,
  ///           std::vector<std::array<double, 3>>, std::span of your struct, ...)
  template <class G, PointLike O, std::ranges::random_access_range R>
    requires std::ranges::sized_range<R> && PointLike<std::ranges::range_value_t<R>>
  InsertStats insert_point_cloud(G& grid, const O& origin, const R& points) {
    const Point3 o = to_point(origin);
    const auto first = std::ranges::begin(points);
    return run(grid, static_cast<std::size_t>(std::ranges::size(points)), [&](std::size_t i) {
      return detail::RayInput{o, to_point(first[static_cast<std::ptrdiff_t>(i)]), true};
    });
  }

  /// Inserts a depth image taken from \p pose (camera to world, optical frame: x right, y down,
  /// z forward). Pixels follow the DepthImage rules: finite > 0 is a return at that z-depth,
  /// +inf is no return (free up to max_range), anything else is invalid and skipped.
  /// \throws InvalidArgument if the intrinsics are invalid or do not match the image size, or
  ///         the image buffer is inconsistent.
  template <class G>
  InsertStats insert_depth_image(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics,
                                 const Pose& pose) {
    intrinsics.validate();
    if (!image.consistent()) throw InvalidArgument("intervox::insert_depth_image: depth buffer size does not match width x height");
    if (image.width != intrinsics.width || image.height != intrinsics.height)
      throw InvalidArgument("intervox::insert_depth_image: image is " + std::to_string(image.width) + "x" +
                            std::to_string(image.height) + " but the intrinsics are " +
                            std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
    const Point3 o = pose.translation();
    const Eigen::Matrix3d r = pose.linear();
    const auto w = static_cast<std::size_t>(image.width);
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    return run(grid, image.depth.size(), [&](std::size_t i) {
      const double z = image.depth[i];
      const Point3 ray = intrinsics.ray(double(i % w), double(i / w));
      if (z > 0.0 && std::isfinite(z)) return detail::RayInput{o, o + r * (ray * z), true};
      if (z == std::numeric_limits<double>::infinity()) return detail::RayInput{o, o + r * ray, false};
      return detail::RayInput{o, Point3(nan, nan, nan), true};  // invalid pixel
    });
  }

  /// Inserts beams with their own origins (Beam::hit false: free up to max_range).
  template <class G>
  InsertStats insert_beams(G& grid, std::span<const Beam> beams) {
    return run(grid, beams.size(), [&](std::size_t i) {
      const Beam& b = beams[i];
      return detail::RayInput{b.origin, b.end, b.hit};
    });
  }

  /// Inserts one ray from \p origin with a return at \p end (a scan of one ray).
  template <class G, PointLike O, PointLike E>
  InsertStats insert_ray(G& grid, const O& origin, const E& end) {
    const detail::RayInput in{to_point(origin), to_point(end), true};
    return run(grid, 1, [&](std::size_t) { return in; });
  }

  /// Bytes held by the scratch buffers.
  std::size_t scratch_bytes() const noexcept {
    std::size_t n = 0;
    for (const auto& m : marks_) n += m.memory_bytes();
    for (const auto& m : box_) n += m.memory_bytes();
    for (const auto& r : rays_) n += r.capacity() * sizeof(detail::PreparedRay);
    for (const auto& b : box_blocks_) n += b.capacity() * sizeof(b[0]);
    return n;
  }

 private:
  static constexpr std::size_t kMinRaysPerThread = 2048;
  /// Scans with more rays prepare each ray twice instead of keeping them (80 bytes per ray)...
  static constexpr std::size_t kMaxKeptRays = std::size_t{1} << 20;
  /// ... the second time this many at a time per thread.
  static constexpr std::size_t kChunkRays = std::size_t{1} << 16;

  unsigned thread_count(std::size_t rays) const {
    unsigned t = options_.threads;
    t = resolve_threads(t);
    t = std::min(t, 64u);
    const std::size_t useful = std::max<std::size_t>(1, rays / kMinRaysPerThread);
    return static_cast<unsigned>(std::min<std::size_t>(t, useful));
  }

  /// Prepares rays [begin, end) of \p source into \p out (counting the skipped ones in \p st),
  /// sums their cost and returns the key box of every voxel their walks visit (that of their
  /// end keys); false if no ray is left.
  /// With \p keep false nothing is stored (\p out is left empty).
  template <class Source>
  static bool prepare_range(const GridGeometry& g, const InsertOptions& o, const Source& source, std::size_t begin,
                            std::size_t end, bool keep, std::vector<detail::PreparedRay>& out, InsertStats& st,
                            Key& lo, Key& hi, std::uint64_t& cost) {
    out.clear();
    cost = 0;
    bool any = false;
    detail::PreparedRay p;
    for (std::size_t i = begin; i < end; ++i) {
      if (!detail::prepare_ray(g, o, source(i), p.v0, p.v1, p.k0, p.k1, p.hit, st)) continue;
      if (!any) lo = hi = p.k0;
      any = true;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min({lo[a], p.k0[a], p.k1[a]});
        hi[a] = std::max({hi[a], p.k0[a], p.k1[a]});
      }
      if (keep) out.push_back(p);
      cost += p.cost();
    }
    return any;
  }

  /// Marks the prepared rays of \p rays into a BoxMarks: hits directly, misses by walk_rays().
  /// (Not a template on the scan's source: the walks are compiled once per program.)
  static void mark_box(detail::RayCursor rays, detail::BoxMarks& marks, detail::WalkKind walk, InsertStats& st) {
    std::uint64_t steps = 0;
    detail::walk_rays(marks, walk, [&](detail::BoxRay& r) {
      while (const detail::PreparedRay* p = rays.next()) {
        if (p->hit) {
          marks.set_hit(marks.id(p->k1));
          ++steps;
        }
        if (detail::make_box_ray(marks, p->v0, p->v1, p->k0, p->k1, r)) {
          steps += static_cast<std::uint64_t>(r.rem) + 1;
          return true;
        }
      }
      return false;
    });
    st.voxel_steps += steps;
  }

  /// Marks the prepared rays of \p rays into a ScanMarks block hash.
  static void mark_hash(detail::RayCursor rays, detail::ScanMarks& marks, InsertStats& st) {
    detail::RayMarker marker(marks);
    while (const detail::PreparedRay* p = rays.next()) st.voxel_steps += marker.mark(p->v0, p->v1, p->k0, p->k1, p->hit);
  }

  /// Runs \p f(t) for t in [0, n) on n threads (t = 0 on the caller), rethrowing the first error.
  template <class F>
  static void parallel(unsigned n, F&& f) {
    run_on_threads(n, f);
  }

  template <class G, class Source>
  InsertStats run(G& grid, std::size_t count, const Source& source) {
    const unsigned nt = thread_count(count);
    if (marks_.size() < nt) marks_.resize(nt);
    if (box_.size() < nt) box_.resize(nt);
    if (rays_.size() < nt) rays_.resize(nt);
    if (box_blocks_.size() < nt) box_blocks_.resize(nt);
    std::vector<InsertStats> part(nt);
    const GridGeometry& g = grid.geometry();

    // Pass 1: validate and prepare every ray, count the skipped ones and find the scan's key
    // box. The prepared rays are kept for pass 2 unless the scan has more than max_kept_rays_
    // (bounded scratch: they are then prepared again). The box decides the marks: two bitmaps
    // over it if small enough, else the block hash. No choice depends on the thread count.
    const bool keep = count <= max_kept_rays_;
    std::vector<Key> lo(nt), hi(nt);
    std::vector<char> any(nt, 0);
    std::vector<std::uint64_t> cost(nt, 0);
    parallel(nt, [&](unsigned t) {
      const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
      any[t] = prepare_range(g, options_, source, b, e, keep, rays_[t], part[t], lo[t], hi[t], cost[t]) ? 1 : 0;
    });
    bool have = false;
    Key blo, bhi;
    for (unsigned t = 0; t < nt; ++t) {
      if (!any[t]) continue;
      if (!have) blo = lo[t], bhi = hi[t];
      have = true;
      for (int a = 0; a < 3; ++a) {
        blo[a] = std::min(blo[a], lo[t][a]);
        bhi[a] = std::max(bhi[a], hi[t][a]);
      }
    }
    bool dense = have && !force_hash_;
    for (unsigned t = 0; dense && t < nt; ++t) dense = box_[t].reset(blo, bhi);

    // Pass 2: mark, each thread a run of the prepared rays of equal walk length (or, not kept,
    // its chunk of pass 1) into its own marks (OR-merged below: the split never changes a result).
    const std::vector<detail::RayPos> runs = nt > 1 && keep ? detail::balanced_runs(rays_, cost, nt)
                                                            : std::vector<detail::RayPos>{{0, 0}, {nt, 0}};
    // Calls f(cursor) with thread t's rays: its run of the kept rays, or its chunk of pass 1
    // prepared again, chunk_rays_ at a time into its ray list.
    auto with_rays = [&](unsigned t, auto&& f) {
      if (keep) {
        f(detail::RayCursor(rays_, runs[t], runs[t + 1]));
        return;
      }
      const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
      for (std::size_t c = b; c < e; c += chunk_rays_) {
        InsertStats counted_before;
        Key l, h;
        std::uint64_t ignored = 0;
        prepare_range(g, options_, source, c, std::min(e, c + chunk_rays_), true, rays_[t], counted_before, l, h, ignored);
        f(detail::RayCursor(rays_, detail::RayPos{t, 0}, detail::RayPos{t, rays_[t].size()}));
      }
    };
    list_.clear();
    if (dense) {
      parallel(nt, [&](unsigned t) { with_rays(t, [&](auto rays) { mark_box(rays, box_[t], walk_, part[t]); }); });
      // The blocks with a mark, the threads' bitmaps OR-ed, in block order (z, y, x): the order
      // of the packed block ids below. Each thread converts a slab of block layers.
      const std::int64_t layers = box_[0].block_layers();
      parallel(nt, [&](unsigned t) {
        auto& out = box_blocks_[t];
        out.clear();
        detail::BoxMarks::for_each_block(box_.data(), nt, layers * t / nt, layers * (t + 1) / nt,
                                         [&](const Key& base, const detail::BlockMarks& m) { out.emplace_back(base, m); });
      });
      for (unsigned t = 0; t < nt; ++t)
        for (const auto& [base, m] : box_blocks_[t]) list_.emplace_back(base, &m);
    } else {
      parallel(nt, [&](unsigned t) { with_rays(t, [&](auto rays) { mark_hash(rays, marks_[t], part[t]); }); });
      detail::ScanMarks& all = marks_[0];
      for (unsigned t = 1; t < nt; ++t) {
        all.merge(marks_[t]);
        marks_[t].clear();
      }
      // Deterministic order: by packed block id, whatever the thread count or ray order.
      order_.resize(all.size());
      for (std::size_t j = 0; j < all.size(); ++j) order_[j] = {all.id(j), static_cast<std::uint32_t>(j)};
      std::sort(order_.begin(), order_.end());
      for (const auto& [id, j] : order_) list_.emplace_back(detail::ScanMarks::block_base(id), &all.marks(j));
    }
    InsertStats st;
    for (const auto& p : part) st += p;
    apply(grid, nt, st);
    if (!dense) marks_[0].clear();
    return st;
  }

  /// Applies the merged marks of list_: a hit where a hit bit is set, else a miss where a miss
  /// bit is set.
  template <class G>
  void apply(G& grid, unsigned nt, InsertStats& st) {
    auto& storage = grid.storage();
    const auto& policy = grid.update_policy();
    using Container = std::remove_reference_t<decltype(storage)>;
    using Cell = typename G::Cell;

    bool by_block = false;
    if constexpr (detail::BlockContainer<Container>) by_block = !storage.box();  // a box may cut blocks
    if (by_block) {
      if constexpr (detail::BlockContainer<Container>) {
      // Allocate every block first (the only step that changes the storage's table), then
      // update the cells, in parallel over blocks.
      blocks_.resize(list_.size());
      for (std::size_t j = 0; j < list_.size(); ++j) {
        auto* b = storage.touch_block(list_[j].first);
        blocks_[j] = b ? static_cast<void*>(b->data()) : nullptr;
      }
      std::vector<InsertStats> part(nt);
      parallel(nt, [&](unsigned t) {
        const std::size_t b = list_.size() * t / nt, e = list_.size() * (t + 1) / nt;
        InsertStats& s = part[t];
        for (std::size_t j = b; j < e; ++j) {
          const detail::BlockMarks& m = *list_[j].second;
          Cell* cells = static_cast<Cell*>(blocks_[j]);
          for (int w = 0; w < 8; ++w) {
            const std::uint64_t h = m.hit[w], f = m.miss[w] & ~h;
            if (!cells) {
              s.outside_bounds += static_cast<std::uint64_t>(std::popcount(h) + std::popcount(f));
              continue;
            }
            Cell* row = cells + 64 * w;
            for (std::uint64_t bits = h; bits; bits &= bits - 1) policy.update(row[std::countr_zero(bits)], Observation::Hit);
            for (std::uint64_t bits = f; bits; bits &= bits - 1) policy.update(row[std::countr_zero(bits)], Observation::Miss);
            s.hits += static_cast<std::uint64_t>(std::popcount(h));
            s.misses += static_cast<std::uint64_t>(std::popcount(f));
          }
        }
      });
      for (const auto& p : part) {
        st.hits += p.hits;
        st.misses += p.misses;
        st.outside_bounds += p.outside_bounds;
      }
      }
    } else {
      // Any other storage (dense), or a bounded sparse one: touch() per cell; distinct cells, so blocks may be split
      // across threads.
      std::vector<InsertStats> part(nt);
      parallel(nt, [&](unsigned t) {
        const std::size_t b = list_.size() * t / nt, e = list_.size() * (t + 1) / nt;
        InsertStats& s = part[t];
        for (std::size_t j = b; j < e; ++j) {
          const detail::BlockMarks& m = *list_[j].second;
          const Key base = list_[j].first;
          for (int w = 0; w < 8; ++w) {
            const std::uint64_t h = m.hit[w], f = m.miss[w] & ~h;
            auto visit = [&](std::uint64_t bits, Observation obs, std::uint64_t& count) {
              for (; bits; bits &= bits - 1) {
                const int i = std::countr_zero(bits);
                const Key k{base.x + (i & 7), base.y + (i >> 3), base.z + w};
                if (Cell* c = storage.touch(k)) {
                  policy.update(*c, obs);
                  ++count;
                } else {
                  ++s.outside_bounds;
                }
              }
            };
            visit(h, Observation::Hit, s.hits);
            visit(f, Observation::Miss, s.misses);
          }
        }
      });
      for (const auto& p : part) {
        st.hits += p.hits;
        st.misses += p.misses;
        st.outside_bounds += p.outside_bounds;
      }
    }
  }

  InsertOptions options_;
  std::vector<detail::ScanMarks> marks_;
  std::vector<detail::BoxMarks> box_;
  std::vector<std::vector<detail::PreparedRay>> rays_;
  std::vector<std::vector<std::pair<Key, detail::BlockMarks>>> box_blocks_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order_;
  std::vector<std::pair<Key, const detail::BlockMarks*>> list_;
  std::vector<void*> blocks_;
  bool force_hash_ = false;
  std::size_t max_kept_rays_ = kMaxKeptRays;
  std::size_t chunk_rays_ = kChunkRays;
  detail::WalkKind walk_ = detail::WalkKind::Fastest;

  friend struct detail::ScanInserterAccess;
};

/// Inserts a point cloud seen from \p origin (see ScanInserter for the semantics). Allocates
/// scratch buffers per call: use a ScanInserter for repeated scans.
/// \tparam G a VoxelGrid; \tparam O PointLike; \tparam R a random-access sized range of PointLike
/// \throws InvalidArgument for invalid options
template <class G, PointLike O, std::ranges::random_access_range R>
  requires std::ranges::sized_range<R> && PointLike<std::ranges::range_value_t<R>>
InsertStats insert_point_cloud(G& grid, const O& origin, const R& points, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_point_cloud(grid, origin, points);
}

/// Inserts a depth image (see ScanInserter::insert_depth_image).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument for invalid options, intrinsics or image
template <class G>
InsertStats insert_depth_image(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics,
                               const Pose& pose, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_depth_image(grid, image, intrinsics, pose);
}

/// Inserts beams with their own origins as one scan (see ScanInserter::insert_beams).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument for invalid options
template <class G>
InsertStats insert_beams(G& grid, std::span<const Beam> beams, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_beams(grid, beams);
}

/// Inserts a single ray with a return at \p end (misses along it, a hit at its end).
/// \tparam G a VoxelGrid; \tparam O, E PointLike
/// \throws InvalidArgument for invalid options
template <class G, PointLike O, PointLike E>
InsertStats insert_ray(G& grid, const O& origin, const E& end, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_ray(grid, origin, end);
}

}  // namespace intervox
