// Material names and workcell object regions.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

TEST_CASE("surface names round-trip and unknown names are rejected", "[sim][material]") {
  for (auto s : {intervox::sim::Surface::Diffuse, intervox::sim::Surface::Absorbing, intervox::sim::Surface::Specular,
                 intervox::sim::Surface::Transparent})
    CHECK(intervox::sim::surface_from_string(intervox::sim::to_string(s)) == s);
  CHECK_THROWS_AS(intervox::sim::surface_from_string("mirror"), intervox::InvalidArgument);
}

TEST_CASE("the workcell names the region of each object, from the table top up", "[sim][workcell]") {
  const auto w = intervox::sim::make_workcell();
  for (const char* name : {"part", "bottle", "box"}) {
    const intervox::Bounds r = w.object_region(name, 0.01);
    INFO(name);
    CHECK(r.valid());
    CHECK(r.min.z() == w.table_center.z());
    CHECK(w.objects.contains(0.5 * (r.min + r.max)));
  }
  const intervox::Bounds part = w.object_region("part", 0.0);
  CHECK(part.contains(w.table_center + intervox::Point3(0.07, 0.0, 0.01)));  // on the ring (outer radius 8 cm)
  CHECK(w.object_region("bottle", 0.0).max.z() > w.object_region("bottle", 0.0).min.z() + 0.25);  // body and neck
  CHECK_THROWS_AS(w.object_region("chair", 0.01), intervox::InvalidArgument);
  CHECK_THROWS_AS(w.object_region("part", -0.1), intervox::InvalidArgument);
}
