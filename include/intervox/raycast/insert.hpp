#pragma once
/// \file
/// Ray insertion: point clouds, depth images, beams and single rays into any VoxelGrid, with the
/// semantics of OctoMap's `insertPointCloud` (exact traversal, per-scan de-duplication, a hit
/// wins over a miss), exact for any number of scans and any number of threads.
///
/// The public API is this header and insert_options.hpp. A scan passes through the internal
/// headers in this order (docs/raycasting.md, "How the insertion works"):
/// detail/prepare_ray.hpp (check each ray) -> detail/schedule.hpp (split the rays between
/// threads) -> detail/box_marks.hpp with detail/walks.hpp (mark the voxels into bitmaps; the
/// portable walks in detail/walk_portable.hpp, the vector ones in detail/walk_x86.hpp, included
/// through vector_walks.hpp), or detail/hash_marks.hpp for scans too large for the bitmaps ->
/// detail/apply_marks.hpp (update the grid).

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/ray.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/detail/apply_marks.hpp>
#include <intervox/raycast/detail/box_marks.hpp>
#include <intervox/raycast/detail/hash_marks.hpp>
#include <intervox/raycast/detail/prepare_ray.hpp>
#include <intervox/raycast/detail/schedule.hpp>
#include <intervox/raycast/detail/walks.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace intervox {

/// A random-access sized range of PointLike points: std::ranges::begin() gives a random-access
/// iterator and std::ranges::size() its length (std::vector<Eigen::Vector3f>,
/// std::vector<std::array<double, 3>>, std::span of your struct, ...). Stated with <iterator>
/// alone, which is lighter to compile than <ranges>.
/// \tparam R the candidate range type
template <class R>
concept PointRange = requires(const R& r) {
  { std::ranges::begin(r) } -> std::random_access_iterator;
  std::ranges::size(r);
}
&&PointLike<std::iter_value_t<decltype(std::ranges::begin(std::declval<const R&>()))>>;

/// The beam of pixel \p i (row-major) of a depth image taken from \p pose: the one rule of
/// depth-image insertion. A finite depth > 0 is a return at pixel_point() (core/ray.hpp); +inf is
/// no return (Beam::hit false, its end one unit along the pixel's ray; insertion cuts it at
/// max_range); anything else is invalid (an end of NaN, skipped by the insertion).
/// Precondition: i < image.depth.size() and image.width > 0.
inline Beam depth_pixel_beam(const DepthImage& image, const PinholeIntrinsics& intrinsics, const Pose& pose,
                             std::size_t i) noexcept {
  const Point3 o = pose.translation();
  const auto w = static_cast<std::size_t>(image.width);
  const double z = image.depth[i];
  const int u = static_cast<int>(i % w), v = static_cast<int>(i / w);
  if (z > 0.0 && std::isfinite(z)) return Beam{o, pixel_point(intrinsics, pose, u, v, z), true};
  if (z == std::numeric_limits<double>::infinity()) return Beam{o, pixel_point(intrinsics, pose, u, v, 1.0), false};
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  return Beam{o, Point3(nan, nan, nan), true};
}

/// The beams of every pixel of \p frame (depth_pixel_beam(), row-major).
/// \throws InvalidArgument for an invalid frame (DepthFrame::validate()).
inline std::vector<Beam> depth_frame_beams(const DepthFrame& frame) {
  frame.validate();
  std::vector<Beam> out(frame.image.depth.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = depth_pixel_beam(frame.image, frame.intrinsics, frame.pose, i);
  return out;
}

namespace detail {

/// An upper bound on the distinct 8^3 blocks the walks of a scan touch: the smaller of
/// (a) the rays' bound, cost / 8 + 4 per ray (a walk of c voxels makes n_x + n_y + n_z = c - 1
///     unit steps, and along an axis of n steps it enters at most ceil(n / 8) new blocks, so it
///     touches at most 1 + (c - 1 + 21) / 8 < 4 + c / 8 blocks), and
/// (b) the blocks of the key box [lo, hi] the rays span, clipped to \p box when one is given
///     (a bounded grid drops the rest).
/// \p cost is the sum of PreparedRay::cost() over the scan's \p rays rays.
inline std::uint64_t scan_block_bound(const Key& lo, const Key& hi, std::uint64_t cost, std::uint64_t rays,
                                      const std::optional<KeyBox>& box) noexcept {
  std::uint64_t by_box = 1;
  for (int a = 0; a < 3; ++a) {
    std::int64_t l = lo[a], h = hi[a];
    if (box) {
      l = std::max<std::int64_t>(l, box->min[a]);
      h = std::min<std::int64_t>(h, box->max[a]);
      if (l > h) return 0;
    }
    by_box *= static_cast<std::uint64_t>((h >> 3) - (l >> 3) + 1);  // <= 2^21 per axis: no overflow
  }
  const std::uint64_t by_rays = cost / 8 + 4 * rays;
  return std::min(by_box, by_rays);
}

/// Throws InvalidArgument if the scan whose rays span the key box [lo, hi] (total walk cost
/// \p cost over \p rays rays) may add more than options.max_grid_bytes to \p grid (a sparse
/// grid; see InsertOptions::max_grid_bytes), naming the rays' extent and the likely cause: \p cause
/// when it is not empty (a depth image's intrinsics, wide_intrinsics_cause()), else depth in
/// millimetres or no max range for rays spanning 500 m or more.
template <class G>
void check_insert_budget(const G& grid, const InsertOptions& options, const Key& lo, const Key& hi, std::uint64_t cost,
                         std::uint64_t rays, const std::string& cause = {}) {
  if (options.max_grid_bytes == kUnlimitedInsertBudget) return;
  using Block = typename G::StorageType::template Container<typename G::Cell>::Block;
  constexpr std::uint64_t per_block = std::uint64_t{sizeof(Block)} + 64;  // cells + table and lists
  const std::uint64_t blocks = scan_block_bound(lo, hi, cost, rays, grid.key_box());
  if (blocks <= options.max_grid_bytes / per_block) return;
  const double res = grid.resolution();
  double span[3], longest = 0.0;
  for (int a = 0; a < 3; ++a) {
    span[a] = (static_cast<double>(hi[a]) - lo[a] + 1) * res;
    longest = std::max(longest, span[a]);
  }
  const auto mib = [](long double b) { return std::to_string(static_cast<std::uint64_t>(b / (1024.0L * 1024.0L))); };
  const auto m = [](double v) {
    std::string t = std::to_string(v);
    return t.substr(0, t.find('.') + 2);
  };
  std::string msg = "this scan may add up to " + mib(static_cast<long double>(blocks) * per_block) +
                    " MiB to the map (" + std::to_string(blocks) +
                    " blocks of 8^3 voxels, an upper bound), more than the insertion budget of " +
                    mib(options.max_grid_bytes) + " MiB (InsertOptions::max_grid_bytes); its " + std::to_string(rays) +
                    " rays span " + m(span[0]) + " x " + m(span[1]) + " x " + m(span[2]) + " m at a resolution of " +
                    m(res * 1000.0) + " mm. ";
  if (!cause.empty())
    msg += cause;
  else if (longest >= 500.0)
    msg += "Rays spanning " + m(longest) + " m: depth in millimetres rather than metres, or no max_range set? ";
  msg += "Set max_range (or bounds), or raise max_grid_bytes if the scan is meant to be that large.";
  ParamCheck("intervox::ScanInserter").fail(msg);
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

}  // namespace detail

/// A reusable inserter: keeps its scratch buffers (the per-scan voxel marks, one set per
/// thread) across scans, so repeated insertion allocates only a few small per-thread lists once
/// warmed up. Scratch is
/// bounded whatever the scan: per thread two bitmaps over the scan's key box (at most 32 MiB;
/// larger boxes use a block hash of at most InsertOptions::max_mark_bytes, marked region by
/// region when a scan needs more), and the prepared rays of scans of up to 2^20 rays (80 bytes
/// each; larger scans prepare each ray twice instead, 2^16 at a time per thread).
/// scratch_bytes() reports the total, release_scratch() frees it. The grid itself grows with
/// what the rays cross (a sparse grid allocates 2 KiB per 8^3 block at 4 bytes per cell): set a
/// max range or bounds when rays may be long. What one call may add to a sparse grid is capped
/// by the insertion budget, InsertOptions::max_grid_bytes (checked before the grid allocates
/// anything; a scan over it throws InvalidArgument and changes nothing).
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
///  - on a bounded grid, updates outside its box are dropped and counted (outside_bounds); a ray
///    is walked only until it leaves the box (detail::clip_to_box(): its walk the same voxel for
///    voxel up to there, so the cells in the box are those of the whole walk), so rays running far
///    past a dense grid cost what they cross of it.
///
/// Determinism: the updated voxels, their values and the grid's block allocation order are the
/// same for every thread count.
///
/// Thread safety: one inserter per thread; the grid needs exclusive access during a call.
///
/// Compile cost: the scan entry points are [[gnu::noinline]] (one call per scan costs nothing),
/// so that an explicit instantiation declaration (`extern template InsertStats
/// ScanInserter::insert_beams<MyGrid>(MyGrid&, std::span<const Beam>);`) keeps the whole insertion
/// pipeline out of every translation unit but the one that instantiates it; GCC instantiates an
/// inline member template for inlining otherwise, extern or not (tests/common/instantiations.hpp
/// does this for the test suites).
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
  /// \tparam R a PointRange (std::vector<Eigen::Vector3f>, std::vector<std::array<double, 3>>,
  ///           std::span of your struct, ...)
  template <OccupancyGrid G, PointLike O, PointRange R>
  [[gnu::noinline]] InsertStats insert_point_cloud(G& grid, const O& origin, const R& points) {
    const Point3 o = to_point(origin);
    const auto first = std::ranges::begin(points);
    return run(grid, static_cast<std::size_t>(std::ranges::size(points)), [&](std::size_t i) {
      return Beam{o, to_point(first[static_cast<std::ptrdiff_t>(i)]), true};
    });
  }

  /// Inserts a depth image taken from \p pose (camera to world, optical frame: x right, y down,
  /// z forward). Pixels follow the DepthImage rules: finite > 0 is a return at that z-depth, at
  /// pixel_point() (core/ray.hpp), +inf is no return (free up to max_range), anything else is
  /// invalid and skipped.
  /// \throws InvalidArgument if the intrinsics are invalid or do not match the image size, the
  ///         image buffer is inconsistent, or the scan exceeds the insertion budget (the message
  ///         names intrinsics whose field of view makes the rays reach far, wide_intrinsics_cause()).
  template <OccupancyGrid G>
  [[gnu::noinline]] InsertStats insert_depth_image(G& grid, const DepthImage& image,
                                                   const PinholeIntrinsics& intrinsics, const Pose& pose) {
    intrinsics.validate();
    if (!image.consistent())
      ParamCheck("intervox::insert_depth_image").fail("depth buffer size does not match width x height");
    if (image.width != intrinsics.width || image.height != intrinsics.height)
      ParamCheck("intervox::insert_depth_image")
          .fail("image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                " but the intrinsics are " + std::to_string(intrinsics.width) + "x" +
                std::to_string(intrinsics.height));
    const std::string cause = detail::wide_intrinsics_cause(intrinsics);
    return run(
        grid, image.depth.size(), [&](std::size_t i) { return depth_pixel_beam(image, intrinsics, pose, i); }, cause);
  }

  /// Inserts a depth frame: its image, seen with its intrinsics from its pose, as
  /// insert_depth_image(grid, frame.image, frame.intrinsics, frame.pose), with the max range the
  /// smaller of the frame's (the camera's range, when finite) and options().max_range (when set):
  /// no-return pixels are free up to the camera's range unless the options cut shorter, and
  /// returns beyond it carry misses only. A frame with max_range = +inf uses the options' alone.
  /// \throws InvalidArgument for an invalid frame (DepthFrame::validate()), or if
  ///         options().min_range exceeds the frame's max range.
  template <OccupancyGrid G>
  [[gnu::noinline]] InsertStats insert_depth_image(G& grid, const DepthFrame& frame) {
    frame.validate();
    const InsertOptions capped = options_.for_frame(frame.max_range);
    if (capped.max_range == options_.max_range)
      return insert_depth_image(grid, frame.image, frame.intrinsics, frame.pose);
    capped.validate();
    return detail::with_options(options_, capped,
                                [&] { return insert_depth_image(grid, frame.image, frame.intrinsics, frame.pose); });
  }

  /// Inserts beams with their own origins (Beam::hit false: free up to max_range).
  template <OccupancyGrid G>
  [[gnu::noinline]] InsertStats insert_beams(G& grid, std::span<const Beam> beams) {
    return run(grid, beams.size(), [&](std::size_t i) { return beams[i]; });
  }

  /// Inserts one ray from \p origin with a return at \p end (a scan of one ray).
  template <OccupancyGrid G, PointLike O, PointLike E>
  [[gnu::noinline]] InsertStats insert_ray(G& grid, const O& origin, const E& end) {
    const Beam in{to_point(origin), to_point(end), true};
    return run(grid, 1, [&](std::size_t) { return in; });
  }

  /// Bytes held by the scratch buffers (kept between scans; see the class comment for bounds).
  std::size_t scratch_bytes() const noexcept {
    std::size_t n = 0;
    for (const auto& m : marks_) n += m.memory_bytes();
    for (const auto& m : box_) n += m.memory_bytes();
    for (const auto& r : rays_) n += r.capacity() * sizeof(detail::PreparedRay);
    for (const auto& b : box_blocks_) n += b.capacity() * sizeof(b[0]);
    return n + order_.capacity() * sizeof(order_[0]) + list_.capacity() * sizeof(list_[0]);
  }

  /// Frees every scratch buffer (the next scan allocates them again). Call it after a large
  /// scan when the memory is needed elsewhere.
  void release_scratch() {
    decltype(marks_)().swap(marks_);
    decltype(box_)().swap(box_);
    decltype(rays_)().swap(rays_);
    decltype(box_blocks_)().swap(box_blocks_);
    decltype(order_)().swap(order_);
    decltype(list_)().swap(list_);
  }

 private:
  static constexpr std::size_t kMinRaysPerThread = 2048;
  /// Scans with more rays prepare each ray twice instead of keeping them (80 bytes per ray)...
  static constexpr std::size_t kMaxKeptRays = std::size_t{1} << 20;
  /// ... the second time this many at a time per thread.
  static constexpr std::size_t kChunkRays = std::size_t{1} << 16;

  unsigned thread_count(std::size_t rays) const {
    const unsigned t = resolve_threads(options_.threads);
    const std::size_t useful = std::max<std::size_t>(1, rays / kMinRaysPerThread);
    return static_cast<unsigned>(std::min<std::size_t>(t, useful));
  }

  /// The key box of the voxels a set of rays visits (that of their end keys), and their cost.
  struct KeyRange {
    Key lo, hi;
    bool any = false;          ///< false: no ray (lo and hi unset)
    std::uint64_t cost = 0;    ///< the voxels the walks enumerate (PreparedRay::cost())
    std::uint64_t walked = 0;  ///< the rays walked
    std::uint64_t hits = 0;    ///< ... of which with a hit

    void add(const Key& a, const Key& b) noexcept {
      if (!any) lo = hi = a;
      any = true;
      for (int i = 0; i < 3; ++i) {
        lo[i] = std::min({lo[i], a[i], b[i]});
        hi[i] = std::max({hi[i], a[i], b[i]});
      }
    }
    void add(const KeyRange& o) noexcept {
      if (o.any) add(o.lo, o.hi);
      cost += o.cost;
      walked += o.walked;
      hits += o.hits;
    }
  };

  /// Prepares rays [begin, end) of \p source into \p out (counting the skipped ones in \p st)
  /// and returns their key range. With \p keep false nothing is stored (\p out is left empty).
  /// With a bounded grid's \p box each ray is cut where it leaves the box (detail::clip_to_box();
  /// the updates left out beyond it are counted in st.outside_bounds).
  template <class Source>
  static KeyRange prepare_range(const GridGeometry& g, const InsertOptions& o, const Source& source, std::size_t begin,
                                std::size_t end, bool keep, std::vector<detail::PreparedRay>& out, InsertStats& st,
                                const std::optional<KeyBox>& box) {
    out.clear();
    KeyRange range;
    for (std::size_t i = begin; i < end; ++i) {
      std::optional<detail::PreparedRay> p = detail::prepare_ray(g, o, source(i), st);
      if (!p) continue;
      if (box && !detail::clip_to_box(*p, *box, st.outside_bounds)) continue;
      range.add(p->k0, p->k1);
      range.cost += p->cost();
      ++range.walked;
      range.hits += p->hit ? 1 : 0;
      if (keep) out.push_back(*p);
    }
    return range;
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

  /// Marks the voxels of the prepared rays of \p rays that lie in \p region into a ScanMarks
  /// block hash; false if the marks outgrew \p max_blocks (they are then incomplete).
  static bool mark_hash(detail::RayCursor rays, detail::ScanMarks& marks, const detail::BlockRegion& region,
                        std::size_t max_blocks) {
    detail::RayMarker marker(marks, region, max_blocks);
    while (const detail::PreparedRay* p = rays.next()) {
      marker.mark(*p);
      if (marker.overflowed()) return false;
    }
    return true;
  }

  /// One scan: pass 1 prepares every ray and finds the scan's key box, pass 2 marks the voxels
  /// (box bitmaps if the box is small enough, else the block hash region by region) and
  /// applies the marks. No choice depends on the thread count.
  /// \p cause: what a budget refusal names as the cause (check_insert_budget()), if not the usual.
  template <OccupancyGrid G, class Source>
  InsertStats run(G& grid, std::size_t count, const Source& source, const std::string& cause = {}) {
    const unsigned nt = thread_count(count);
    if (marks_.size() < nt) marks_.resize(nt);
    if (box_.size() < nt) box_.resize(nt);
    if (rays_.size() < nt) rays_.resize(nt);
    if (box_blocks_.size() < nt) box_blocks_.resize(nt);
    const GridGeometry& g = grid.geometry();

    // Pass 1: validate and prepare every ray in contiguous chunks, count the skipped ones and
    // find the scan's key box. The prepared rays are kept for pass 2 unless the scan has more
    // than max_kept_rays_ (bounded scratch: they are then prepared again).
    const bool keep = count <= max_kept_rays_;
    std::vector<InsertStats> part(nt);
    std::vector<KeyRange> ranges(nt);
    const std::optional<KeyBox>& box = grid.key_box();  // a bounded grid: rays are cut at its box
    run_on_threads(nt, [&](unsigned t) {
      const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
      ranges[t] = prepare_range(g, options_, source, b, e, keep, rays_[t], part[t], box);
    });
    InsertStats st;
    KeyRange scan;
    std::vector<std::uint64_t> cost(nt);
    for (unsigned t = 0; t < nt; ++t) {
      st += part[t];
      scan.add(ranges[t]);
      cost[t] = ranges[t].cost;
    }
    if (!scan.any) return st;
    // The insertion budget, once per call, before pass 2 allocates anything in the map.
    if constexpr (!G::StorageType::kBounded)
      detail::check_insert_budget(grid, options_, scan.lo, scan.hi, scan.cost, st.rays, cause);

    // Each thread's rays for pass 2: runs of the kept rays of equal walk length.
    const std::vector<detail::RayPos> runs =
        nt > 1 && keep ? detail::balanced_runs(rays_, cost, nt) : std::vector<detail::RayPos>{{0, 0}, {nt, 0}};
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
        prepare_range(g, options_, source, c, std::min(e, c + chunk_rays_), true, rays_[t], counted_before, box);
        f(detail::RayCursor(rays_, detail::RayPos{t, 0}, detail::RayPos{t, rays_[t].size()}));
      }
    };
    bool dense = !force_hash_;
    for (unsigned t = 0; dense && t < nt; ++t) dense = box_[t].reset(scan.lo, scan.hi);
    if (dense) {
      st += mark_and_apply_box(grid, nt, with_rays);
    } else {
      st.voxel_steps = scan.cost - scan.walked + scan.hits;  // every walk's misses, plus the hits
      st += mark_and_apply_hash(grid, nt, scan, with_rays);
    }
    return st;
  }

  /// Pass 2 with the box bitmaps: each thread marks its rays into its own bitmaps, which are
  /// OR-merged (the split changes nothing), each thread assembling the blocks of a slab of
  /// block layers, in block order (z, y, x): the order of the packed block ids. Returns the
  /// voxel steps and what apply_marks() counted.
  template <OccupancyGrid G, class WithRays>
  InsertStats mark_and_apply_box(G& grid, unsigned nt, WithRays& with_rays) {
    std::vector<InsertStats> part(nt);
    run_on_threads(nt, [&](unsigned t) { with_rays(t, [&](auto rays) { mark_box(rays, box_[t], walk_, part[t]); }); });
    const std::int64_t layers = box_[0].block_layers();
    run_on_threads(nt, [&](unsigned t) {
      auto& out = box_blocks_[t];
      out.clear();
      detail::BoxMarks::for_each_block(
          box_.data(), nt, layers * t / nt, layers * (t + 1) / nt,
          [&](const Key& base, const detail::BlockMarks& m) { out.emplace_back(base, m); });
    });
    list_.clear();
    for (unsigned t = 0; t < nt; ++t)
      for (const auto& [base, m] : box_blocks_[t]) list_.emplace_back(base, &m);
    InsertStats st = detail::apply_marks(grid, std::span<const detail::MarkedBlock>(list_), nt);
    for (const auto& p : part) st += p;
    return st;
  }

  /// Pass 2 with the block hash, one region of the key box at a time: a region whose marks
  /// would hold more than max_mark_blocks() blocks is split in halves and each half marked and
  /// applied in turn (depth first), so the scratch stays bounded however long the rays are.
  /// Each voxel lies in exactly one region, so the per-scan semantics hold. Whether a region is
  /// split depends only on its distinct blocks (a thread that overflows implies the union
  /// does), so the regions, and the block allocation order, are the same for every thread
  /// count. Returns what apply_marks() counted.
  template <OccupancyGrid G, class WithRays>
  InsertStats mark_and_apply_hash(G& grid, unsigned nt, const KeyRange& scan, WithRays& with_rays) {
    InsertStats st;
    const std::size_t max_blocks = max_mark_blocks();
    std::vector<detail::BlockRegion> pending{detail::BlockRegion{{scan.lo.x >> 3, scan.lo.y >> 3, scan.lo.z >> 3},
                                                                 {scan.hi.x >> 3, scan.hi.y >> 3, scan.hi.z >> 3}}};
    std::vector<char> fits(nt);
    while (!pending.empty()) {
      const detail::BlockRegion region = pending.back();
      pending.pop_back();
      run_on_threads(nt, [&](unsigned t) {
        fits[t] = 1;
        with_rays(t, [&](auto rays) {
          if (fits[t]) fits[t] = mark_hash(rays, marks_[t], region, max_blocks) ? 1 : 0;
        });
      });
      detail::ScanMarks& all = marks_[0];
      bool fit = std::all_of(fits.begin(), fits.end(), [](char f) { return f != 0; });
      for (unsigned t = 1; t < nt; ++t) {
        fit = fit && all.merge(marks_[t], max_blocks);
        marks_[t].clear();
      }
      if (!fit && region.blocks() > 1) {  // (one block always fits: max_blocks >= 1)
        all.clear();
        const auto [first, second] = region.split();
        pending.push_back(second);
        pending.push_back(first);
        continue;
      }
      // Deterministic order: by packed block id, whatever the thread count or ray order.
      order_.resize(all.size());
      for (std::size_t j = 0; j < all.size(); ++j) order_[j] = {all.id(j), static_cast<std::uint32_t>(j)};
      std::sort(order_.begin(), order_.end());
      list_.clear();
      for (const auto& [id, j] : order_) list_.emplace_back(detail::ScanMarks::block_base(id), &all.marks(j));
      st += detail::apply_marks(grid, std::span<const detail::MarkedBlock>(list_), nt);
      all.clear();
    }
    return st;
  }

  /// The block budget of the hash marks per thread (InsertOptions::max_mark_bytes), at least 1.
  std::size_t max_mark_blocks() const noexcept {
    return std::max<std::size_t>(1, options_.max_mark_bytes / detail::ScanMarks::kBytesPerBlock);
  }

  InsertOptions options_;
  std::vector<detail::ScanMarks> marks_;
  std::vector<detail::BoxMarks> box_;
  std::vector<std::vector<detail::PreparedRay>> rays_;
  std::vector<std::vector<std::pair<Key, detail::BlockMarks>>> box_blocks_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order_;
  std::vector<detail::MarkedBlock> list_;
  bool force_hash_ = false;
  std::size_t max_kept_rays_ = kMaxKeptRays;
  std::size_t chunk_rays_ = kChunkRays;
  detail::WalkKind walk_ = detail::WalkKind::Fastest;

  friend struct detail::ScanInserterAccess;
};

/// Inserts a point cloud seen from \p origin (see ScanInserter for the semantics). Allocates
/// scratch buffers per call: use a ScanInserter for repeated scans.
/// \tparam G a VoxelGrid; \tparam O PointLike; \tparam R a PointRange
/// \throws InvalidArgument for invalid options
template <OccupancyGrid G, PointLike O, PointRange R>
InsertStats insert_point_cloud(G& grid, const O& origin, const R& points, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_point_cloud(grid, origin, points);
}

/// Inserts a depth image (see ScanInserter::insert_depth_image).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument for invalid options, intrinsics or image
template <OccupancyGrid G>
InsertStats insert_depth_image(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics, const Pose& pose,
                               const InsertOptions& options = {}) {
  return ScanInserter(options).insert_depth_image(grid, image, intrinsics, pose);
}

/// Inserts a depth frame (see ScanInserter::insert_depth_image(G&, const DepthFrame&)): the
/// max range is the smaller of the frame's and \p options.max_range.
/// \tparam G a VoxelGrid
/// \throws InvalidArgument for invalid options or an invalid frame
template <OccupancyGrid G>
InsertStats insert_depth_image(G& grid, const DepthFrame& frame, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_depth_image(grid, frame);
}

/// Inserts beams with their own origins as one scan (see ScanInserter::insert_beams).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument for invalid options
template <OccupancyGrid G>
InsertStats insert_beams(G& grid, std::span<const Beam> beams, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_beams(grid, beams);
}

/// Inserts a single ray with a return at \p end (misses along it, a hit at its end).
/// \tparam G a VoxelGrid; \tparam O, E PointLike
/// \throws InvalidArgument for invalid options
template <OccupancyGrid G, PointLike O, PointLike E>
InsertStats insert_ray(G& grid, const O& origin, const E& end, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_ray(grid, origin, end);
}

}  // namespace intervox
