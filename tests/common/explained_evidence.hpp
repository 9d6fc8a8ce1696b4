#pragma once
// Shared by the explained-channel tests: every voxel's evidence of a channel, as a map to compare.
#include <intervox/explain/explained_space.hpp>

#include <map>

namespace test {

/// The evidence of every voxel \p s holds evidence for.
inline std::map<intervox::Key, intervox::EvidenceCell> evidence_map(const intervox::ExplainedSpace& s) {
  std::map<intervox::Key, intervox::EvidenceCell> m;
  s.for_each([&](const intervox::Key& k, const intervox::EvidenceCell& e) { m[k] = e; });
  return m;
}

}  // namespace test
