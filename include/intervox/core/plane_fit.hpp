#pragma once
/// \file
/// The least-squares plane through a set of points: its normal, the eigenvector of the smallest
/// eigenvalue of the points' covariance. Shared by the conflict regions' normals
/// (analysis/conflicts.hpp) and the arm's glint targets (plan/normal_seeking.hpp).
///
/// Thread safety: a pure function.

#include <intervox/core/point.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>

namespace intervox {

/// The unit normal of the least-squares plane through \p points, or nothing if there are fewer
/// than 3 or they lie (nearly) on a line: the middle eigenvalue of their covariance not above
/// \p min_spread times the largest (or, when \p min_spread is 0, not above 1e-12 * max(1, largest)).
/// The sign is deterministic: the component of largest magnitude is positive; callers orient it.
inline std::optional<Point3> plane_normal(std::span<const Point3> points, double min_spread = 0.0) {
  if (points.size() < 3) return std::nullopt;
  Point3 mean = Point3::Zero();
  for (const Point3& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Point3& p : points) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  const Eigen::Vector3d ev = es.eigenvalues();  // ascending
  const double floor = min_spread > 0 ? min_spread * ev[2] : 1e-12 * std::max(1.0, ev[2]);
  if (!(ev[1] > floor)) return std::nullopt;  // (nearly) collinear
  Point3 n = es.eigenvectors().col(0).normalized();
  int a = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(n[i]) > std::abs(n[a])) a = i;
  if (n[a] < 0) n = -n;
  return n;
}

}  // namespace intervox
