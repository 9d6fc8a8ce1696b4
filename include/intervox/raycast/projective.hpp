#pragma once
/// \file
/// Projective insertion of depth images: every voxel of the camera's view frustum is projected
/// into the image once and freed by the depth of the pixel its centre falls in, instead of
/// walking every pixel's ray (insert.hpp); the voxel of each return gets its hit as in the exact
/// insertion. For dense depth images at sensor rate; the exact insertion stays the one that
/// equals OctoMap. docs/raycasting.md ("Projective insertion") compares the two, with the
/// agreement and the speed measured.
///
/// The rule, per frame:
///  - hits: the voxel of each return (a finite depth > 0 whose range lies in [min_range,
///    max_range], max_range when one is set), the voxel the exact insertion hits (the same
///    end point, pixel_point(), and the same key);
///  - misses: each voxel whose centre c lies in front of the camera (z-depth z > 0 in the optical
///    frame) and projects into pixel (u, v) = (floor(fx x / z + cx + 1/2), floor(fy y / z + cy +
///    1/2)) of the image gets a miss if z <= d - b for a pixel with a return at z-depth d, where b
///    is the surface band (surface_band voxel edges, measured along the pixel's ray and converted
///    to z-depth): voxels just in front of a surface, and all behind it, get no miss. A pixel whose
///    return lies beyond max_range, or without a return (+inf) when a max range is set, frees its
///    voxels up to max_range along its ray (as the exact insertion frees a cut ray);
///  - nothing from a return closer than min_range, a no-return pixel without a max range, an
///    invalid pixel (NaN, 0, negative, -inf) or a voxel whose centre projects outside the image;
///  - each voxel is updated at most once per frame, a hit winning over a miss (as the exact
///    insertion).
/// Voxels are visited block by block (8^3), and whole blocks (and 64^3 superblocks) are skipped
/// from their corners' projections: when they lie behind the camera, outside the image, or
/// behind the reach of every pixel they cover (a max-reach pyramid of the image).
///
/// Where it differs from the exact insertion (measured in docs/raycasting.md): a voxel a ray only
/// grazes, whose centre projects into another pixel, gets no miss from that ray; far from the
/// camera, where a voxel covers several pixels, one of them decides its miss (the exact walks
/// leave gaps there instead, between diverging rays); voxels near the camera whose centres
/// project outside the image (the camera's own voxel among them) get nothing.
///
/// Explained free space (explain/) does not apply: its classes belong to beams, walked through
/// the map one by one, and a projective frame has no beams. Use ExplainedSpace's insertion
/// (exact) where the explained channel is wanted.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/raycast/detail/apply_marks.hpp>
#include <intervox/raycast/detail/block_marks.hpp>
#include <intervox/raycast/detail/projected_frame.hpp>
#include <intervox/raycast/detail/walks.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace intervox {

/// Default surface band of projective insertion: voxel edges in front of a return whose voxels
/// get no miss (docs/raycasting.md measures the choice against the exact insertion).
inline constexpr double kDefaultSurfaceBand = 0.5;

/// The most 64^3 superblocks the key box of a frame's view frustum may span, whatever the insertion
/// budget (kUnlimitedInsertBudget included): each is projected once before any block is, and each
/// costs 4 bytes of scratch, so this bounds a frame's cost at a few seconds and 64 MiB (a box of
/// 256^3 superblocks: 820 m a side at 5 cm, 330 m at 2 cm; a frame near that frees far more voxels
/// than any budget holds). A frustum the image's reach makes larger (a return hundreds of
/// kilometres away with the budget off: 1.7e15 superblocks) is refused; the exact insertion walks
/// such rays one by one.
inline constexpr std::uint64_t kMaxProjectiveSuperblocks = std::uint64_t{1} << 24;

namespace detail {

struct ScanInserterAccess;  // insert.hpp: test access (set_walk() chooses the scalar form here)

}  // namespace detail

/// A reusable projective inserter (see the file comment for the rule and how it differs from
/// the exact insertion): keeps its scratch (the pixel reach, its pyramid and the block marks)
/// across frames.
///
/// Options: InsertOptions' max_range, min_range, threads and max_grid_bytes mean what they mean
/// for the exact insertion (max_mark_bytes is not used); \p surface_band is the surface band in
/// voxel edges (default kDefaultSurfaceBand; see the file comment).
///
/// Statistics: every pixel is counted once, in `rays` (and `truncated` when cut at max range or
/// without a return) or in skipped_invalid, skipped_min_range, skipped_no_max_range or
/// skipped_key_range (a return outside the key range, or every pixel when the camera is);
/// `voxel_steps` counts the voxels projected into the image; hits and misses as for the exact
/// insertion; outside_bounds: the marked voxels of blocks that a bounded grid's box cuts and the
/// returns outside it (blocks wholly outside the box are never visited).
///
/// Memory: the scratch holds about 20 bytes per pixel (its reach, ray table and pyramid, and the
/// voxel of its return), 160 bytes per visited 8^3 block, 2 KiB per 64^3 superblock with a
/// visited block and 4 bytes per superblock of the frustum's box. The visited blocks are those of
/// the frustum in front of the measured surfaces, so cost and scratch grow with the observed
/// volume, (range / resolution)^3: for long ranges the exact insertion costs less. On a sparse
/// grid, a frame whose blocks to update exceed the insertion budget (max_grid_bytes, at the
/// grid's bytes per block) throws InvalidArgument before the grid changes, as does a frame whose
/// frustum box holds more 64^3 superblocks than the budget has blocks (depth in millimetres read
/// as metres, or no max range with far returns). A dense grid clips the frustum to its box.
/// Whatever the budget (kUnlimitedInsertBudget included), a frustum box of more than
/// kMaxProjectiveSuperblocks superblocks (after that clip) is refused the same way: its voxels are
/// too many to project in bounded time. A max range beyond the key range frees what the key range
/// holds (a max range of 1e39, beyond the largest float, frees the same voxels as one of 1e6 m).
///
/// Determinism: the blocks are applied in block order (z, y, x), as by the exact insertion,
/// and nothing depends on the thread count: the grid (values and block allocation order) is
/// bit-identical for any number of threads.
///
/// Thread safety: one inserter per thread; the grid needs exclusive access during a call.
class ProjectiveInserter {
 public:
  /// \throws InvalidArgument for invalid options (InsertOptions::validate()) or a hit band that
  ///         is not finite and >= 0.
  explicit ProjectiveInserter(const InsertOptions& options = {}, double surface_band = kDefaultSurfaceBand) {
    set_options(options, surface_band);
  }

  const InsertOptions& options() const noexcept { return options_; }
  double surface_band() const noexcept { return surface_band_; }
  /// \throws InvalidArgument as the constructor.
  void set_options(const InsertOptions& options, double surface_band = kDefaultSurfaceBand) {
    options.validate();
    ParamCheck("intervox::ProjectiveInserter").nonnegative("surface_band", surface_band);
    options_ = options;
    surface_band_ = surface_band;
  }

  /// Inserts a depth image taken from \p pose (camera to world, optical frame) by projection.
  /// A pose with a NaN or infinite entry skips every pixel (counted in skipped_invalid), as the
  /// exact insertion skips rays with a NaN origin.
  /// \tparam G a VoxelGrid (any update policy and storage)
  /// \throws InvalidArgument if the intrinsics are invalid or do not match the image size, the
  ///         image buffer is inconsistent, the pose is finite but not rigid, or the frame exceeds
  ///         the insertion budget or kMaxProjectiveSuperblocks (see the class comment); the grid is
  ///         then unchanged.
  template <OccupancyGrid G>
  [[gnu::noinline]] InsertStats insert_depth_image(G& grid, const DepthImage& image,
                                                   const PinholeIntrinsics& intrinsics, const Pose& pose) {
    intrinsics.validate();
    if (!image.consistent())
      ParamCheck("intervox::insert_depth_image_projective").fail("depth buffer size does not match width x height");
    if (image.width != intrinsics.width || image.height != intrinsics.height)
      ParamCheck("intervox::insert_depth_image_projective")
          .fail("image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                " but the intrinsics are " + std::to_string(intrinsics.width) + "x" +
                std::to_string(intrinsics.height));
    InsertStats st;
    if (!pose.matrix().allFinite()) {
      st.skipped_invalid = image.depth.size();
      return st;
    }
    detail::validate_pose(pose, "projective insertion pose");
    if (!grid.geometry().try_key(pose.translation())) {
      st.skipped_key_range = image.depth.size();
      return st;
    }
    frame_.build(grid.geometry(), image, intrinsics, pose, options_, surface_band_ * grid.resolution(),
                 resolve_threads(options_.threads), st);
    cause_ = detail::wide_intrinsics_cause(intrinsics);
    if (frame_.far() <= 0.0f && frame_.hits().empty()) return st;
    return st += run(grid);
  }

  /// Inserts a depth frame by projection, with the max range the smaller of the frame's and
  /// options().max_range (as ScanInserter::insert_depth_image(G&, const DepthFrame&)).
  /// \throws InvalidArgument for an invalid frame, if options().min_range exceeds the frame's
  ///         max range, or as the image overload.
  template <OccupancyGrid G>
  [[gnu::noinline]] InsertStats insert_depth_image(G& grid, const DepthFrame& frame) {
    frame.validate();
    const InsertOptions capped = options_.for_frame(frame.max_range);
    capped.validate();
    return detail::with_options(options_, capped,
                                [&] { return insert_depth_image(grid, frame.image, frame.intrinsics, frame.pose); });
  }

  /// Bytes held by the scratch (kept between frames).
  std::size_t scratch_bytes() const noexcept {
    std::size_t n = frame_.memory_bytes() + (supers_.capacity() + blocks_.capacity()) * sizeof(Key) +
                    (super_slot_.capacity() + slots_.capacity()) * sizeof(std::int32_t) +
                    marks_.capacity() * sizeof(detail::BlockMarks) + list_.capacity() * sizeof(detail::MarkedBlock);
    for (const auto& c : candidates_) n += c.capacity() * sizeof(Key);
    return n;
  }
  /// Frees the scratch (the next frame allocates it again).
  void release_scratch() {
    const detail::WalkKind walk = walk_;
    *this = ProjectiveInserter(options_, surface_band_);
    walk_ = walk;
  }

 private:
  /// Blocks per superblock edge (a superblock is 64^3 voxels).
  static constexpr int kSuper = 8;

  /// The bytes a new block costs a sparse grid (cells plus table overhead); 0 for a dense one.
  template <OccupancyGrid G>
  static std::uint64_t bytes_per_block() noexcept {
    if constexpr (G::StorageType::kBounded) {
      return 0;
    } else {
      using Block = typename G::StorageType::template Container<typename G::Cell>::Block;
      return std::uint64_t{sizeof(Block)} + 64;
    }
  }

  [[noreturn]] void over_budget(const char* what, std::uint64_t blocks, std::uint64_t budget, double far,
                                double res) const {
    ParamCheck("intervox::insert_depth_image_projective")
        .fail(std::string("this frame's view frustum ") + what + " (" + std::to_string(blocks) +
              " blocks of 8^3 voxels) than the insertion budget of " + std::to_string(budget >> 20) +
              " MiB allows (InsertOptions::max_grid_bytes); it reaches " + std::to_string(far) +
              " m in z-depth at a resolution of " + std::to_string(res * 1000.0) + " mm. " +
              (cause_.empty() ? std::string("Depth in millimetres read as metres, or no max_range with far returns? ")
                              : cause_) +
              "Set max_range, or raise max_grid_bytes if the frame is meant to be that large.");
  }

  [[noreturn]] static void too_many_superblocks(std::uint64_t supers, double far, double res) {
    ParamCheck("intervox::insert_depth_image_projective")
        .fail("this frame's view frustum spans " + std::to_string(supers) +
              " superblocks of 64^3 voxels, more than projective insertion visits (kMaxProjectiveSuperblocks = " +
              std::to_string(kMaxProjectiveSuperblocks) + ", whatever the insertion budget); it reaches " +
              std::to_string(far) + " m in z-depth at a resolution of " + std::to_string(res * 1000.0) +
              " mm. Set max_range, or insert such frames with the exact insertion (ScanInserter), which walks "
              "each pixel's ray alone.");
  }

  /// The key box of a frame's frustum (and its hits), and the 64^3 superblocks it spans: the first
  /// per axis (in superblocks), the count per axis and in all.
  struct FrustumBox {
    Key lo, hi;
    std::int64_t s_lo[3], s_n[3];
    std::uint64_t s_total = 1;
  };
  /// The insertion budget in blocks (check false: none, a bounded grid or kUnlimitedInsertBudget).
  struct BlockBudget {
    bool check = false;
    std::uint64_t blocks = ~std::uint64_t{0};
  };

  template <OccupancyGrid G>
  InsertStats run(G& grid) {
    const GridGeometry& g = grid.geometry();
    const double res = g.resolution();
    FrustumBox box;
    if (!frustum_key_box(grid, box)) return {};
    const BlockBudget budget = block_budget<G>();
    count_superblocks(box, budget, res);
    collect_superblocks(g, box);
    const unsigned nt = resolve_threads(options_.threads);
    const std::size_t total = collect_blocks(g, box, nt, budget, res);
    const std::uint64_t steps = classify_blocks(g, total, nt);
    InsertStats st;
    add_hits(box, st);
    if (budget.check && blocks_.size() > budget.blocks)
      over_budget("has more blocks to update", blocks_.size(), options_.max_grid_bytes, frame_.far(), res);
    st += apply_blocks(grid, nt);
    st.voxel_steps += steps;
    return st;
  }

  /// The box of the centres of [k0, k0 + n).
  static std::pair<Point3, Point3> centre_box(const GridGeometry& g, const Key& k0, std::int32_t n) noexcept {
    return std::pair{g.center(k0), g.center(Key{k0.x + n - 1, k0.y + n - 1, k0.z + n - 1})};
  }
  /// \p n threads for \p n items, at least 1 and at most \p nt.
  static unsigned capped(std::size_t n, unsigned nt) noexcept {
    return static_cast<unsigned>(std::clamp<std::size_t>(n, 1, nt));
  }

  /// The key box of the frustum, clipped to the key range and to a bounded grid's box, in \p box;
  /// false if the clip leaves nothing.
  template <OccupancyGrid G>
  bool frustum_key_box(const G& grid, FrustumBox& box) const {
    const GridGeometry& g = grid.geometry();
    const double res = g.resolution();
    const Bounds fb = frame_.frustum_bounds();
    Key& lo = box.lo;
    Key& hi = box.hi;
    for (int a = 0; a < 3; ++a) {
      const double l = std::floor((fb.min[a] - g.origin()[a]) / res) - 1,
                   h = std::floor((fb.max[a] - g.origin()[a]) / res) + 1;
      lo[a] = static_cast<std::int32_t>(std::clamp(l, -double(kKeyLimit), double(kKeyLimit) - 1));
      hi[a] = static_cast<std::int32_t>(std::clamp(h, -double(kKeyLimit), double(kKeyLimit) - 1));
    }
    for (const Key& k : frame_.hits())
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], k[a]);
        hi[a] = std::max(hi[a], k[a]);
      }
    if (const auto& kb = grid.key_box()) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::max(lo[a], kb->min[a]);
        hi[a] = std::min(hi[a], kb->max[a]);
        if (lo[a] > hi[a]) return false;
      }
    }
    return true;
  }

  template <OccupancyGrid G>
  BlockBudget block_budget() const noexcept {
    const std::uint64_t per_block = bytes_per_block<G>();
    BlockBudget b;
    b.check = !G::StorageType::kBounded && options_.max_grid_bytes != kUnlimitedInsertBudget;
    b.blocks = b.check ? options_.max_grid_bytes / std::max<std::uint64_t>(per_block, 1) : ~std::uint64_t{0};
    return b;
  }

  /// The superblocks of \p box (s_lo, s_n, s_total); throws if they exceed the budget or
  /// kMaxProjectiveSuperblocks.
  void count_superblocks(FrustumBox& box, const BlockBudget& budget, double res) const {
    for (int a = 0; a < 3; ++a) {
      box.s_lo[a] = box.lo[a] >> 6;
      box.s_n[a] = (box.hi[a] >> 6) - box.s_lo[a] + 1;
      box.s_total *= static_cast<std::uint64_t>(box.s_n[a]);  // < 2^18 per axis: no overflow
    }
    if (budget.check && box.s_total > budget.blocks)
      over_budget("spans more superblocks", box.s_total, options_.max_grid_bytes, frame_.far(), res);
    if (box.s_total > kMaxProjectiveSuperblocks) too_many_superblocks(box.s_total, frame_.far(), res);
  }

  /// Superblocks (64^3 voxels) of the box that may be updated, in z, y, x order, in supers_.
  void collect_superblocks(const GridGeometry& g, const FrustumBox& box) {
    supers_.clear();
    for (std::int64_t z = 0; z < box.s_n[2]; ++z)
      for (std::int64_t y = 0; y < box.s_n[1]; ++y)
        for (std::int64_t x = 0; x < box.s_n[0]; ++x) {
          const Key s{static_cast<std::int32_t>((box.s_lo[0] + x) * 64),
                      static_cast<std::int32_t>((box.s_lo[1] + y) * 64),
                      static_cast<std::int32_t>((box.s_lo[2] + z) * 64)};
          const auto [a, b] = centre_box(g, s, 64);
          if (frame_.may_update(a, b)) supers_.push_back(s);
        }
  }

  /// Blocks of those superblocks inside the box that may be updated, each thread a contiguous
  /// run of superblocks; concatenated in superblock order (the same for any thread count) in
  /// blocks_. Returns their number; throws if it exceeds the budget.
  std::size_t collect_blocks(const GridGeometry& g, const FrustumBox& box, unsigned nt, const BlockBudget& budget,
                             double res) {
    const Key& lo = box.lo;
    const Key& hi = box.hi;
    const unsigned nc = capped(supers_.size(), nt);
    if (candidates_.size() < nc) candidates_.resize(nc);
    run_on_threads(nc, [&](unsigned t) {
      auto& out = candidates_[t];
      out.clear();
      const std::size_t b = supers_.size() * t / nc, e = supers_.size() * (t + 1) / nc;
      for (std::size_t j = b; j < e; ++j) {
        const Key& s = supers_[j];
        for (int bz = 0; bz < kSuper; ++bz)
          for (int by = 0; by < kSuper; ++by)
            for (int bx = 0; bx < kSuper; ++bx) {
              const Key base{s.x + 8 * bx, s.y + 8 * by, s.z + 8 * bz};
              if (base.x + 7 < lo.x || base.x > hi.x || base.y + 7 < lo.y || base.y > hi.y || base.z + 7 < lo.z ||
                  base.z > hi.z)
                continue;
              const auto [a, c] = centre_box(g, base, 8);
              if (frame_.may_update(a, c)) out.push_back(base);
            }
      }
    });
    std::size_t total = 0;
    for (unsigned t = 0; t < nc; ++t) total += candidates_[t].size();
    if (budget.check && total > budget.blocks)
      over_budget("has more blocks to update", total, options_.max_grid_bytes, frame_.far(), res);
    blocks_.resize(total);
    std::size_t at = 0;
    for (unsigned t = 0; t < nc; ++t) {
      std::copy(candidates_[t].begin(), candidates_[t].end(), blocks_.begin() + static_cast<std::ptrdiff_t>(at));
      at += candidates_[t].size();
    }
    return total;
  }

  /// Classifies every voxel of the \p total candidate blocks into marks_, split evenly between
  /// the threads; the AVX2 form where the program chose the vector walks (use_vector_walks()) and
  /// walk_ allows it. Returns the voxels projected into the image.
  std::uint64_t classify_blocks(const GridGeometry& g, std::size_t total, unsigned nt) {
    const detail::WalkKind kind = detail::resolve_walk(walk_);
    const bool vector = kind == detail::WalkKind::Avx512 || kind == detail::WalkKind::Avx2;
    marks_.resize(total);
    const unsigned nm = capped(total / 16, nt);
    std::vector<std::uint64_t> seen(nm, 0);
    run_on_threads(nm, [&](unsigned t) {
      const std::size_t b = total * t / nm, e = total * (t + 1) / nm;
      for (std::size_t j = b; j < e; ++j) seen[t] += frame_.classify_block(g, blocks_[j], marks_[j], vector);
    });
    std::uint64_t steps = 0;
    for (const auto s : seen) steps += s;
    return steps;
  }

  /// The slot of the block at \p base in the superblock index (-1: not a candidate yet), its
  /// superblock's 512 slots allocated on first use.
  std::int32_t& block_slot(const FrustumBox& box, const Key& base) {
    const std::uint64_t si = static_cast<std::uint64_t>(
        ((std::int64_t{base.z >> 6} - box.s_lo[2]) * box.s_n[1] + (std::int64_t{base.y >> 6} - box.s_lo[1])) *
            box.s_n[0] +
        (std::int64_t{base.x >> 6} - box.s_lo[0]));
    std::int32_t& slot = super_slot_[si];
    if (slot < 0) {
      slot = static_cast<std::int32_t>(slots_.size() / 512);
      slots_.resize(slots_.size() + 512, -1);
    }
    return slots_[static_cast<std::size_t>(slot) * 512 +
                  static_cast<std::size_t>(((base.z >> 3) & 7) * 64 + ((base.y >> 3) & 7) * 8 + ((base.x >> 3) & 7))];
  }

  /// The hits: the voxel of each return (the exact insertion's), found through a superblock
  /// index; blocks that the projection skipped are added after the others, in pixel order.
  void add_hits(const FrustumBox& box, InsertStats& st) {
    const Key& lo = box.lo;
    const Key& hi = box.hi;
    super_slot_.assign(box.s_total, -1);
    slots_.clear();
    const std::size_t total = blocks_.size();
    for (std::size_t j = 0; j < total; ++j) block_slot(box, blocks_[j]) = static_cast<std::int32_t>(j);
    for (const Key& k : frame_.hits()) {
      if (k.x < lo.x || k.x > hi.x || k.y < lo.y || k.y > hi.y || k.z < lo.z || k.z > hi.z) {
        ++st.outside_bounds;  // (only where a bounded grid's box cut the key box)
        continue;
      }
      const Key base{k.x & ~7, k.y & ~7, k.z & ~7};
      std::int32_t& j = block_slot(box, base);
      if (j < 0) {
        j = static_cast<std::int32_t>(blocks_.size());
        blocks_.push_back(base);
        marks_.push_back(detail::BlockMarks{});
      }
      detail::set_bit(marks_[static_cast<std::size_t>(j)].hit,
                      (k.x - base.x) + 8 * (k.y - base.y) + 64 * (k.z - base.z));
    }
  }

  /// Applies the marked blocks to \p grid in block order (z, y, x), as the exact insertion
  /// applies its marks: the grid's blocks are allocated in the same order, and a saved and
  /// loaded grid keeps it.
  template <OccupancyGrid G>
  InsertStats apply_blocks(G& grid, unsigned nt) {
    list_.clear();
    for (std::size_t j = 0; j < blocks_.size(); ++j) {
      const detail::BlockMarks& m = marks_[j];
      std::uint64_t any = 0;
      for (int w = 0; w < 8; ++w) any |= m.hit[w] | m.miss[w];
      if (any) list_.emplace_back(blocks_[j], &m);
    }
    std::sort(list_.begin(), list_.end(), [](const detail::MarkedBlock& a, const detail::MarkedBlock& b) {
      return std::tie(a.first.z, a.first.y, a.first.x) < std::tie(b.first.z, b.first.y, b.first.x);
    });
    return detail::apply_marks(grid, std::span<const detail::MarkedBlock>(list_), capped(list_.size() / 16, nt));
  }

  InsertOptions options_;
  double surface_band_ = kDefaultSurfaceBand;
  std::string cause_;  ///< what a budget refusal of the current frame names (wide_intrinsics_cause())
  detail::ProjectedFrame frame_;
  std::vector<Key> supers_;
  std::vector<std::vector<Key>> candidates_;
  std::vector<Key> blocks_;
  std::vector<detail::BlockMarks> marks_;
  std::vector<detail::MarkedBlock> list_;
  std::vector<std::int32_t> super_slot_;  // per superblock of the key box: its slot, or -1
  std::vector<std::int32_t> slots_;       // per slot, 512 blocks: the index into blocks_, or -1
  detail::WalkKind walk_ = detail::WalkKind::Fastest;

  friend struct detail::ScanInserterAccess;
};

/// Inserts a depth image by projection (see ProjectiveInserter). Allocates scratch per call: use
/// a ProjectiveInserter for a stream of frames.
/// \tparam G a VoxelGrid
/// \throws InvalidArgument as ProjectiveInserter::insert_depth_image
template <OccupancyGrid G>
InsertStats insert_depth_image_projective(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics,
                                          const Pose& pose, const InsertOptions& options = {},
                                          double surface_band = kDefaultSurfaceBand) {
  return ProjectiveInserter(options, surface_band).insert_depth_image(grid, image, intrinsics, pose);
}

/// Inserts a depth frame by projection, the max range the smaller of the frame's and
/// \p options.max_range (see ProjectiveInserter).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument as ProjectiveInserter::insert_depth_image
template <OccupancyGrid G>
InsertStats insert_depth_image_projective(G& grid, const DepthFrame& frame, const InsertOptions& options = {},
                                          double surface_band = kDefaultSurfaceBand) {
  return ProjectiveInserter(options, surface_band).insert_depth_image(grid, frame);
}

}  // namespace intervox
