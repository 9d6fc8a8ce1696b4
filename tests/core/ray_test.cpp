// The one pixel-to-ray rule (core/ray.hpp) against closed forms.
#include <catch2/catch.hpp>
#include <intervox/core/ray.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <vector>

namespace iv = intervox;

namespace {
iv::PinholeIntrinsics small_camera() {
  iv::PinholeIntrinsics k;
  k.width = 7;
  k.height = 5;
  k.fx = 4.0;
  k.fy = 5.0;
  k.cx = 3.0;
  k.cy = 2.0;
  return k;
}
iv::Pose some_pose() {
  iv::Pose p = iv::Pose::Identity();
  p.translate(iv::Point3(1.0, -2.0, 0.5));
  p.rotate(Eigen::AngleAxisd(0.7, iv::Point3(0.3, -0.2, 1.0).normalized()));
  return p;
}
}  // namespace

TEST_CASE("a pixel's ray starts at the camera and points through the pixel centre, unit length", "[core][ray]") {
  const auto k = small_camera();
  // The principal point (3, 2) looks along the optical axis.
  const iv::Ray axis = iv::pixel_ray(k, iv::Pose::Identity(), 3, 2, 4.0);
  CHECK(axis.origin == iv::Point3::Zero());
  CHECK(axis.direction == iv::Point3::UnitZ());
  CHECK(axis.range == 4.0);
  // Pixel (5, 0): ((5 - 3) / 4, (0 - 2) / 5, 1) = (0.5, -0.4, 1), normalised.
  const iv::Ray r = iv::pixel_ray(k, iv::Pose::Identity(), 5, 0);
  const double n = std::sqrt(0.25 + 0.16 + 1.0);
  CHECK(r.direction.x() == Approx(0.5 / n));
  CHECK(r.direction.y() == Approx(-0.4 / n));
  CHECK(r.direction.z() == Approx(1.0 / n));
  CHECK(r.range == std::numeric_limits<double>::infinity());
  // At a pose: the camera-frame ray moved rigidly.
  const iv::Pose p = some_pose();
  const iv::Ray w = iv::pixel_ray(k, p, 5, 0, 2.0);
  CHECK((w.origin - p.translation()).norm() == 0.0);
  CHECK((w.direction - p.linear() * r.direction).norm() < 1e-15);
  CHECK(w.direction.norm() == Approx(1.0).epsilon(1e-15));
  CHECK((w.at(2.0) - (p.translation() + 2.0 * w.direction)).norm() == 0.0);
}

TEST_CASE("a pixel's point at z-depth d lies on its ray with camera-frame z equal to d", "[core][ray]") {
  const auto k = small_camera();
  const iv::Pose p = some_pose();
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      const iv::Point3 x = iv::pixel_point(k, p, u, v, 2.5);
      const iv::Point3 camera_frame = p.inverse() * x;
      REQUIRE(camera_frame.z() == Approx(2.5).epsilon(1e-12));
      const iv::Ray r = iv::pixel_ray(k, p, u, v);
      const double t = (x - r.origin).dot(r.direction);
      REQUIRE(t == Approx(2.5 * k.ray(u, v).norm()).epsilon(1e-12));
      REQUIRE((r.at(t) - x).norm() < 1e-12);
    }
}

TEST_CASE("a stride keeps a centred pattern of pixels, row-major", "[core][ray]") {
  CHECK(iv::strided_first(64, 1) == 0);
  CHECK(iv::strided_first(64, 4) == 1);   // 1, 5, ..., 61: margins 1 and 2
  CHECK(iv::strided_first(48, 8) == 3);   // 3, 11, ..., 43: margins 3 and 4
  CHECK(iv::strided_first(640, 8) == 3);  // 3, ..., 635: margins 3 and 4
  CHECK(iv::strided_first(7, 3) == 0);    // 0, 3, 6: margins 0 and 0
  CHECK(iv::strided_first(5, 10) == 2);   // the centre pixel alone
  CHECK(iv::strided_first(0, 3) == 0);
  CHECK_THROWS_AS(iv::strided_first(10, 0), iv::InvalidArgument);
  // Margins of every size and stride differ by at most one, the larger one at the end.
  for (int size = 1; size <= 40; ++size)
    for (int stride = 1; stride <= 12; ++stride) {
      const int first = iv::strided_first(size, stride);
      const int last = first + (size - 1 - first) / stride * stride;
      const int tail = size - 1 - last;
      REQUIRE(first >= 0);
      REQUIRE(tail - first >= 0);
      REQUIRE(tail - first <= 1);
    }

  const auto k = small_camera();  // 7 x 5 at stride 3: u = 0, 3, 6 and v = 0, 3 (margins 0, 1)
  const iv::Pose p = some_pose();
  const auto rays = iv::camera_rays(k, p, 3, 1.5);
  REQUIRE(rays.size() == 6);
  std::size_t i = 0;
  for (int v : {0, 3})
    for (int u : {0, 3, 6}) {
      const iv::Ray expected = iv::pixel_ray(k, p, u, v, 1.5);
      REQUIRE(rays[i].direction == expected.direction);
      REQUIRE(rays[i].origin == expected.origin);
      REQUIRE(rays[i].range == 1.5);
      ++i;
    }
  CHECK(iv::camera_rays(k, p).size() == 35);
  CHECK_THROWS_AS(iv::camera_rays(k, p, 0), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::camera_rays(iv::PinholeIntrinsics{}, p), iv::InvalidArgument);
}
