#pragma once
/// \file
/// What the mobile planner remembers of the frontiers (and passages) it tried: those given up and
/// how often each was selected. Frontiers within frontier_radius of each other count as the same
/// one. Thread safety: a value type.

#include <intervox/core/key.hpp>

#include <algorithm>
#include <utility>
#include <vector>

namespace intervox {

/// The frontiers given up and their visit counts (MobilePlanner's memory between calls).
class FrontierMemory {
 public:
  /// True if the frontier (or passage) column \p f lies within \p radius (m; columns of
  /// \p resolution) of one in \p tried or of one given up: it counts as the same one.
  bool near_tried_or_given_up(const Key& f, const std::vector<Key>& tried, double resolution, double radius) const {
    const double fr = radius / resolution;
    const auto near = [&](const Key& k) {
      return double(k.x - f.x) * double(k.x - f.x) + double(k.y - f.y) * double(k.y - f.y) <= fr * fr;
    };
    return std::any_of(tried.begin(), tried.end(), near) || std::any_of(given_up_.begin(), given_up_.end(), near);
  }
  /// Gives frontier \p f up.
  void give_up(const Key& f) { given_up_.push_back(f); }
  /// The visit count of the frontier \p f stands for (the first one counted within \p radius),
  /// a new one at 0 if none.
  int& visits(const Key& f, double resolution, double radius) {
    const double fr = radius / resolution;
    for (auto& [k, n] : visits_)
      if (double(k.x - f.x) * double(k.x - f.x) + double(k.y - f.y) * double(k.y - f.y) <= fr * fr) return n;
    visits_.push_back({f, 0});
    return visits_.back().second;
  }

 private:
  std::vector<Key> given_up_;
  std::vector<std::pair<Key, int>> visits_;
};

}  // namespace intervox
