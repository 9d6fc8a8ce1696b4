// A type that is not a grid (here a plain map of keys) handed to an algorithm that takes any grid
// must be rejected by the OccupancyGrid concept at the call.
// expect: required for the satisfaction of .*OccupancyGrid<G>.* \[with G = KeyMap\]
#include <intervox/raycast/cast.hpp>

#include <map>

struct KeyMap {
  std::map<intervox::Key, float> cells;
};

int main() {
  KeyMap map;
  const auto hit = intervox::cast_ray(map, intervox::Point3(0, 0, 0), intervox::Point3(1, 0, 0));
  return hit.hit() ? 0 : 1;
}
