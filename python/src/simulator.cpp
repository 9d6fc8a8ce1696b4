/// \file
/// The simulator: materials, scenes (the lab room, the symmetric rooms, the workcell), sensors and
/// rigs, and simulated scans returned as numpy arrays (depth images, beams).

#include "common.hpp"

#include <intervox/sim/sim.hpp>

#include <cstring>
#include <optional>
#include <sstream>
#include <string>

namespace intervox::python {
template <>
inline constexpr const char* kGuardedName<sim::SimulatedRig> = "SimulatedRig";
}  // namespace intervox::python

#include "guard.hpp"

namespace intervox::python {

namespace {

using namespace intervox::sim;

py::array_t<float> depth_to_numpy(const DepthImage& img) {
  py::array_t<float> a({static_cast<py::ssize_t>(img.height), static_cast<py::ssize_t>(img.width)});
  if (!img.depth.empty()) std::memcpy(a.mutable_data(), img.depth.data(), img.depth.size() * sizeof(float));
  return a;
}

/// The options of a simulation call; \p body only for the rig calls (the camera call passes none).
SimOptions sim_options(unsigned threads, bool glint = false, double glint_angle = kDefaultGlintAngle,
                       const std::optional<RobotBody>& body = std::nullopt) {
  SimOptions o;
  o.threads = threads;
  o.glint = glint;
  o.glint_angle = glint_angle;
  o.body = body;
  o.validate();
  return o;
}

constexpr const char* kGlintDoc =
    "glint: near-normal glint (off by default): a beam within glint_angle [rad, default 3 degrees] of a mirror's or\n"
    "polished metal's normal returns from that surface (its own range) instead of the folded phantom.";
constexpr const char* kBodyDoc =
    "body: a RobotBody placed at each body pose (None by default): it appears in mirrors; beams ignore it up to\n"
    "their first reflection, so the cameras' direct rays never meet it.";

TriangleMesh to_mesh(const py::handle& vertices, const py::handle& triangles) {
  const PointsView v(vertices, "mesh vertices");
  auto t = py::array_t<std::int64_t, py::array::forcecast>::ensure(triangles);
  if (!t || t.ndim() != 2 || t.shape(1) != 3)
    throw InvalidArgument("mesh triangles: expected an integer array of shape (M, 3)");
  TriangleMesh mesh;
  for (std::size_t i = 0; i < v.size(); ++i) mesh.vertices.push_back(v[i]);
  auto r = t.unchecked<2>();
  for (py::ssize_t i = 0; i < t.shape(0); ++i) {
    std::array<std::uint32_t, 3> tri{};
    for (int a = 0; a < 3; ++a) {
      if (r(i, a) < 0 || r(i, a) > 0xFFFFFFFFLL) throw InvalidArgument("mesh triangles: negative or too large index");
      tri[static_cast<std::size_t>(a)] = static_cast<std::uint32_t>(r(i, a));
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

/// SimulatedRig that keeps its own copy of nothing but a reference to the scene (kept alive by
/// pybind11's keep_alive).
py::tuple simulated_scan(SimulatedRig& rig, const py::object& body) {
  const Pose p = to_pose(body, "body pose");
  std::vector<Beam> beams;
  {
    py::gil_scoped_release release;
    beams = rig(p);
  }
  return beams_to_numpy(beams);
}

}  // namespace

void bind_simulator(py::module_& m) {
  // ---- materials -----------------------------------------------------------------------------
  py::enum_<Surface>(m, "Surface", "How a surface answers a beam (thesis 5.2.2).")
      .value("DIFFUSE", Surface::Diffuse, "the true distance plus Gaussian noise")
      .value("ABSORBING", Surface::Absorbing, "no return, except now and then a diffuse one")
      .value("SPECULAR", Surface::Specular,
             "a mirror or polished metal: reflects the beam (or, as an option, a random range)")
      .value("TRANSPARENT", Surface::Transparent,
             "glass: reflects by Fresnel, else a diffuse return or the beam passes on");
  py::enum_<SpecularModel>(m, "SpecularModel", "What a specular surface does with a beam it does not return directly.")
      .value("REFLECT", SpecularModel::Reflect, "mirror reflection with exact geometry (the default)")
      .value("RANDOM_RANGE", SpecularModel::RandomRange, "the first edition's uniformly random range");
  // Lambdas rather than member pointers: the factories may gain defaulted parameters.
  py::class_<Material>(m, "Material", "A surface material with its noise model; build it with the factory functions.")
      .def(py::init<>(), "The default diffuse material.")
      .def_static(
          "diffuse", [](double sigma, double per_metre) { return Material::diffuse(sigma, per_metre); },
          py::arg("sigma") = 0.01, py::arg("sigma_per_metre") = 0.0,
          "A diffuse surface with noise sigma + sigma_per_metre * range [m].")
      .def_static(
          "absorbing", [](double p_return, double sigma) { return Material::absorbing(p_return, sigma); },
          py::arg("p_return") = 0.05, py::arg("sigma") = 0.01,
          "An absorbing surface that returns (diffusely) with probability p_return.")
      .def_static(
          "specular", [] { return Material::specular(); },
          "The specular surface of the current model: a perfect mirror.")
      .def_static(
          "mirror", [] { return Material::mirror(); }, "A perfect mirror: every beam is reflected.")
      .def_static(
          "polished_metal",
          [](double p0, double exponent, double sigma) { return Material::polished_metal(p0, exponent, sigma); },
          py::arg("p0") = Material::kPolishedP0, py::arg("exponent") = Material::kPolishedExponent,
          py::arg("sigma") = 0.01,
          "Polished metal: a direct return with probability p0 * cos(theta)**exponent, otherwise mirror reflection.")
      .def_static(
          "specular_random_range", [] { return Material::specular_random_range(); },
          "The first edition's specular surface: a uniformly random range.")
      .def_static(
          "transparent",
          [](double p_pass, double sigma, double refractive_index) {
            return Material::transparent(p_pass, sigma, refractive_index);
          },
          py::arg("p_pass") = 0.5, py::arg("sigma") = 0.01, py::arg("refractive_index") = 1.5,
          "Glass: reflects by Schlick's Fresnel approximation, otherwise passes a beam with probability p_pass.")
      .def_static(
          "transparent_without_fresnel",
          [](double p_pass, double sigma) { return Material::transparent_without_fresnel(p_pass, sigma); },
          py::arg("p_pass") = 0.5, py::arg("sigma") = 0.01,
          "The first edition's transparent surface (no Fresnel reflection).")
      .def_static(
          "named", [](const std::string& name) { return material_from_string(name); }, py::arg("name"),
          "The material of a command-line name: diffuse, absorbing, specular (= mirror), polished-metal, transparent "
          "(= glass), specular-random, transparent-no-fresnel.")
      .def_static(
          "of", [](Surface s) { return Material::of(s); }, py::arg("surface"),
          "The default material of a surface kind.")
      .def_readonly("surface", &Material::surface)
      .def_readonly("sigma", &Material::sigma)
      .def_readonly("sigma_per_metre", &Material::sigma_per_metre)
      .def_readonly("p_return", &Material::p_return)
      .def_readonly("p_pass", &Material::p_pass)
      .def_readonly("specular_model", &Material::specular_model)
      .def_readonly("p_direct", &Material::p_direct, "specular: direct-return probability at normal incidence")
      .def_readonly("lobe_exponent", &Material::lobe_exponent, "specular: exponent n of cos^n theta")
      .def_readonly("fresnel", &Material::fresnel, "transparent: reflect by Schlick's Fresnel approximation first")
      .def_readonly("refractive_index", &Material::refractive_index, "transparent: refractive index for Schlick's R0")
      .def("__repr__", [](const Material& mat) {
        std::ostringstream s;
        s << "Material(" << to_string(mat.surface) << ", sigma=" << mat.sigma
          << ", sigma_per_metre=" << mat.sigma_per_metre << ", p_return=" << mat.p_return << ", p_pass=" << mat.p_pass
          << ")";
        return s.str();
      });

  // ---- scenes --------------------------------------------------------------------------------
  py::class_<Scene>(m, "Scene",
                    "A static scene of objects with materials for the simulator. Every add_* validates its input\n"
                    "(ValueError) and returns the object's id. Thread safety: do not change a scene while simulating.")
      .def(py::init<>())
      .def(
          "add_box",
          [](Scene& s, const py::object& box, const Material& mat, std::string name) {
            return s.add_box(to_bounds(box), mat, std::move(name));
          },
          py::arg("box"), py::arg("material") = Material{}, py::arg("name") = "",
          "An axis-aligned box (Bounds or (min, max)).")
      .def(
          "add_oriented_box",
          [](Scene& s, const py::object& pose, const Point3& half, const Material& mat, std::string name) {
            return s.add_oriented_box(to_pose(pose), half, mat, std::move(name));
          },
          py::arg("pose"), py::arg("half_extents"), py::arg("material") = Material{}, py::arg("name") = "",
          "A box of half extents centred at pose's translation, rotated by pose (4x4).")
      .def("add_quad", &Scene::add_quad, py::arg("corner"), py::arg("edge_u"), py::arg("edge_v"),
           py::arg("material") = Material{}, py::arg("name") = "", "A parallelogram corner + s * edge_u + t * edge_v.")
      .def("add_sphere", &Scene::add_sphere, py::arg("center"), py::arg("radius"), py::arg("material") = Material{},
           py::arg("name") = "")
      .def("add_cylinder", &Scene::add_cylinder, py::arg("base"), py::arg("top"), py::arg("radius"),
           py::arg("material") = Material{}, py::arg("name") = "", "A capped cylinder between two disk centres.")
      .def(
          "add_mesh",
          [](Scene& s, const py::object& vertices, const py::object& triangles, const Material& mat, std::string name) {
            return s.add_mesh(to_mesh(vertices, triangles), mat, std::move(name));
          },
          py::arg("vertices"), py::arg("triangles"), py::arg("material") = Material{}, py::arg("name") = "",
          "A triangle mesh: vertices (N, 3), triangles (M, 3) vertex indices; a closed mesh is a solid.")
      .def("__len__", &Scene::size)
      .def("find", &Scene::find, py::arg("name"), "The id of the first object of that name, or None.")
      .def("name", &Scene::name, py::arg("id"))
      .def("material", &Scene::material, py::arg("id"))
      .def("set_material", &Scene::set_material, py::arg("id"), py::arg("material"))
      .def("object_bounds", &Scene::object_bounds, py::arg("id"))
      .def_property_readonly("bounds", &Scene::bounds, "bounds of every object")
      .def(
          "intersect",
          [](const Scene& s, const Point3& o, const Point3& d, double tmin, double tmax) -> py::object {
            const auto hit = s.intersect(o, d, tmin, tmax);
            if (!hit) return py::none();
            return py::make_tuple(hit->t, hit->object);
          },
          py::arg("origin"), py::arg("direction"), py::arg("tmin") = 0.0,
          py::arg("tmax") = std::numeric_limits<double>::infinity(),
          "The first surface met by origin + t * direction for t in (tmin, tmax]: (t, object id) or None.")
      .def(
          "inside",
          [](const Scene& s, const py::object& points) {
            const PointsView pts(points, "inside: points");
            auto out = make_array<bool>(pts.shape());
            bool* w = out.mutable_data();
            for (std::size_t i = 0; i < pts.size(); ++i) w[i] = s.inside(pts[i]);
            return out;
          },
          py::arg("points"), "True (shape (...)) where a point lies inside a solid object.")
      .def(
          "ground_truth",
          [](const Scene& s, double resolution, const py::object& region, const Point3& origin) {
            std::vector<Key> keys;
            const GridGeometry g(resolution, origin);
            const Bounds b = to_bounds(region);
            {
              py::gil_scoped_release release;
              keys = s.ground_truth(g, b);
            }
            py::array_t<std::int32_t> a({static_cast<py::ssize_t>(keys.size()), py::ssize_t{3}});
            auto w = a.mutable_unchecked<2>();
            for (std::size_t i = 0; i < keys.size(); ++i)
              for (int k = 0; k < 3; ++k) w(static_cast<py::ssize_t>(i), k) = keys[i][k];
            return a;
          },
          py::arg("resolution"), py::arg("region"), py::arg("origin") = Point3(Point3::Zero()),
          "The keys (M, 3) int32 of the occupied voxels of a grid with this geometry inside region.");

  py::class_<LabRoom>(m, "LabRoom", "The thesis' lab room (Fig. 5.2b) and what a planner needs to know about it.")
      .def_readonly("scene", &LabRoom::scene, py::return_value_policy::reference_internal)
      .def_readonly("closet", &LabRoom::closet,
                    "id of the closet whose material the experiments vary (its front quad with closet_front_only)")
      .def_readonly("closet_body", &LabRoom::closet_body, "id of the closet's box")
      .def_readonly("door", &LabRoom::door)
      .def_readonly("interior", &LabRoom::interior, "the free inside [0, 8] x [0, 6] x [0, 3]")
      .def_readonly("start", &LabRoom::start, "a free spot on the floor for the base")
      .def_readonly("annex_interior", &LabRoom::annex_interior, "with annex=True: the annex's free inside, else None")
      .def_readonly("annex_doorway", &LabRoom::annex_doorway, "with annex=True: the doorway's gap in the east wall")
      .def_readonly("window", &LabRoom::window, "with window=True: the window's gap in the south wall, else None");
  m.def(
      "make_lab_room",
      [](const Material& closet, const Material& door, const Material& rest, bool ceiling, bool annex, bool window,
         bool closet_front_only) {
        LabRoomOptions o;
        o.closet_material = closet;
        o.door_material = door;
        o.default_material = rest;
        o.ceiling = ceiling;
        o.annex = annex;
        o.window = window;
        o.closet_front_only = closet_front_only;
        return make_lab_room(o);
      },
      py::kw_only(), py::arg("closet_material") = Material::diffuse(), py::arg("door_material") = Material::diffuse(),
      py::arg("default_material") = Material::diffuse(), py::arg("ceiling") = true, py::arg("annex") = false,
      py::arg("window") = false, py::arg("closet_front_only") = false,
      "The ~8 x 6 x 3 m lab room for the mobile base (see docs/platforms.md). annex: an open doorway in the east\n"
      "wall to an annex room; window: a window without glass in the south wall, real things outside;\n"
      "closet_front_only: only the closet's front has closet_material (a wardrobe with a mirror door).");
  py::class_<SymmetricRooms>(
      m, "SymmetricRooms",
      "Two 4 x 4 x 2.6 m rooms, mirror images about the shared wall's mid-plane x = 4.1, joined by a "
      "doorway (see docs/platforms.md).")
      .def_readonly("scene", &SymmetricRooms::scene, py::return_value_policy::reference_internal)
      .def_property_readonly(
          "rooms", [](const SymmetricRooms& r) { return std::vector<Bounds>(r.rooms.begin(), r.rooms.end()); },
          "the free insides [west [0, 4] x [0, 4] x [0, 2.6], east [4.2, 8.2] x [0, 4] x [0, 2.6]]")
      .def_readonly("doorway", &SymmetricRooms::doorway, "the doorway's opening in the shared wall")
      .def_readonly("symmetry_x", &SymmetricRooms::symmetry_x, "the mirror plane x = 4.1 of the two rooms")
      .def_readonly("mirror", &SymmetricRooms::mirror,
                    "with mirror=True: the panel's bounds (in the plane x = 4.1), else None")
      .def_readonly("niche", &SymmetricRooms::niche, "with mirror=True: the niche before the panel, else None")
      .def_readonly("mirror_object", &SymmetricRooms::mirror_object,
                    "with mirror=True: the panel's object id, else None")
      .def_readonly("start", &SymmetricRooms::start, "a free spot for the base in the west room")
      .def("reflect", &SymmetricRooms::reflect, py::arg("point"),
           "The mirror image of a point about the plane x = 4.1.");
  m.def(
      "make_symmetric_rooms",
      [](bool mirror, const Material& mirror_material, const Material& rest, bool ceiling) {
        SymmetricRoomsOptions o;
        o.mirror = mirror;
        o.mirror_material = mirror_material;
        o.default_material = rest;
        o.ceiling = ceiling;
        return make_symmetric_rooms(o);
      },
      py::kw_only(), py::arg("mirror") = false, py::arg("mirror_material") = Material::mirror(),
      py::arg("default_material") = Material::diffuse(), py::arg("ceiling") = true,
      "Two mirror-symmetric rooms joined by a doorway: the hard case of mirror detection. mirror: a doorway-sized\n"
      "panel of mirror_material beside the doorway in the symmetry plane, showing the west room's image, which is\n"
      "the east room itself.");
  py::class_<Workcell>(m, "Workcell", "The object workcell for the arm and what an arm planner needs to know about it.")
      .def_readonly("scene", &Workcell::scene, py::return_value_policy::reference_internal)
      .def_readonly("part", &Workcell::part)
      .def_readonly("bottle", &Workcell::bottle)
      .def_readonly("bottle_neck", &Workcell::bottle_neck)
      .def_readonly("box", &Workcell::box)
      .def_readonly("table", &Workcell::table)
      .def_readonly("table_center", &Workcell::table_center)
      .def_readonly("objects", &Workcell::objects)
      .def("object_region", &Workcell::object_region, py::arg("object"), py::arg("margin"),
           "The box an arm models for 'part', 'bottle' or 'box', grown by margin, from the table top up.");
  m.def(
      "make_workcell",
      [](const Material& part, const Material& bottle, const Material& box, const Material& rest, int segments) {
        WorkcellOptions o;
        o.part_material = part;
        o.bottle_material = bottle;
        o.box_material = box;
        o.default_material = rest;
        o.ring_segments = segments;
        return make_workcell(o);
      },
      py::kw_only(), py::arg("part_material") = Material::polished_metal(),
      py::arg("bottle_material") = Material::transparent(), py::arg("box_material") = Material::diffuse(),
      py::arg("default_material") = Material::diffuse(), py::arg("ring_segments") = 48,
      "The ~1.5 m workcell with a ring-shaped part, a bottle and a box on a table.");

  // ---- sensors and rigs ----------------------------------------------------------------------
  py::class_<DepthCamera>(m, "DepthCamera", "A pinhole depth camera with a range window.")
      .def_static("make", &DepthCamera::make, py::arg("width"), py::arg("height"), py::arg("fov_x"), py::arg("fov_y"),
                  py::arg("min_range"), py::arg("max_range"), "Opening angles in radians.")
      .def_static("o3d100", &DepthCamera::o3d100,
                  "The ifm O3D-100 of the thesis' mobile base: 64 x 48, 40 x 30 degrees.")
      .def_readonly("intrinsics", &DepthCamera::intrinsics)
      .def_readonly("min_range", &DepthCamera::min_range)
      .def_readonly("max_range", &DepthCamera::max_range);
  py::class_<LaserStriper>(m, "LaserStriper",
                           "A laser line scanner: samples along x of its frame, looking along z; a camera `baseline` "
                           "along y (negative: on the -y side) triangulates the line.")
      .def_static(
          "make", &LaserStriper::make, py::arg("samples"), py::arg("opening"), py::arg("min_range"),
          py::arg("max_range"), py::arg("baseline") = LaserStriper::kDefaultBaseline,
          py::arg("camera_crossing") = LaserStriper::kDefaultCameraCrossing,
          "Opening in radians, ranges in metres; the camera `baseline` along y (signed; 0: coaxial) and the range "
          "`camera_crossing` where its axis crosses the laser plane default to scancontrol_2700()'s.")
      .def_static("scancontrol_2700", &LaserStriper::scancontrol_2700,
                  "The thesis' arm striper: 640 samples over 14 degrees; camera baseline 0.15 m crossing the laser "
                  "plane at 0.45 m (representative values, not the datasheet's).")
      .def_readonly("samples", &LaserStriper::samples)
      .def_readonly("opening", &LaserStriper::opening)
      .def_readonly("min_range", &LaserStriper::min_range)
      .def_readonly("max_range", &LaserStriper::max_range)
      .def_readonly("baseline", &LaserStriper::baseline)
      .def_readonly("camera_crossing", &LaserStriper::camera_crossing)
      .def("camera_position", &LaserStriper::camera_position,
           "The camera's position (0, baseline, 0) in the sensor frame.")
      .def("triangulation_angle", &LaserStriper::triangulation_angle,
           "atan(|baseline| / camera_crossing) [rad]: the angle between the laser's and the camera's axes.");
  py::class_<SensorRig>(m, "SensorRig", "Sensors rigidly mounted on one body (mount: sensor optical frame to body).")
      .def(py::init<>())
      .def(
          "add",
          [](SensorRig& r, const Sensor& sensor, const py::object& mount, std::string name) {
            return r.add(sensor, to_pose(mount, "mount"), std::move(name));
          },
          py::arg("sensor"), py::arg("mount"), py::arg("name") = "",
          "Adds a DepthCamera or LaserStriper; returns its index.")
      .def("__len__", &SensorRig::size)
      .def("beam_count", py::overload_cast<>(&SensorRig::beam_count, py::const_), "Beams of all sensors.")
      .def(
          "sensor_pose",
          [](const SensorRig& r, std::size_t s, const py::object& body) {
            return from_pose(r.sensor_pose(s, to_pose(body, "body pose")));
          },
          py::arg("sensor"), py::arg("body"), "World pose (4x4) of a sensor for the body at `body`.")
      .def_static(
          "mobile_base",
          [](double length, double width, double camera_height, double pitch, const DepthCamera& camera) {
            MobileBaseOptions o;
            o.length = length;
            o.width = width;
            o.camera_height = camera_height;
            o.pitch = pitch;
            o.camera = camera;
            return SensorRig::mobile_base(o);
          },
          py::kw_only(), py::arg("length") = 0.6, py::arg("width") = 0.4, py::arg("camera_height") = 0.5,
          py::arg("pitch") = 0.0, py::arg("camera") = DepthCamera::o3d100(),
          "The thesis' omniRob: eight O3D-100 cameras around the base at knee height.")
      .def_static(
          "arm",
          [](const LaserStriper& striper, double standoff) {
            ArmOptions o;
            o.striper = striper;
            o.standoff = standoff;
            return SensorRig::arm(o);
          },
          py::kw_only(), py::arg("striper") = LaserStriper::scancontrol_2700(), py::arg("standoff") = 0.1,
          "The thesis' KR16: one striper on the flange.");

  py::class_<RobotBody>(
      m, "RobotBody",
      "The robot's own body for the simulator (a box in the body frame with a material): placed at each\n"
      "body pose by the rig calls, it appears in mirrors; beams ignore it up to their first reflection.")
      .def(py::init([](const py::object& box, const Material& material) {
             RobotBody b;
             b.box = to_bounds(box);
             b.material = material;
             b.validate();
             return b;
           }),
           py::arg("box"), py::arg("material") = Material::diffuse(),
           "A body box (Bounds or (min, max)) in the body frame.")
      .def_static(
          "mobile_base",
          [](double length, double width, double height, const Material& material) {
            MobileBaseOptions o;
            o.length = length;
            o.width = width;
            return RobotBody::mobile_base(o, height, material);
          },
          py::kw_only(), py::arg("length") = 0.6, py::arg("width") = 0.4, py::arg("height") = kDefaultBodyHeight,
          py::arg("material") = Material::diffuse(),
          "The mobile base's body: its footprint centred on the body origin, from the floor up to height.")
      .def_readonly("box", &RobotBody::box)
      .def_readonly("material", &RobotBody::material);

  m.def(
      "look_at",
      [](const Point3& eye, const Point3& target, const Point3& up) { return from_pose(look_at(eye, target, up)); },
      py::arg("eye"), py::arg("target"), py::arg("up") = Point3(Point3::UnitZ()),
      "The optical-frame pose (4x4, z forward, y down) at eye looking at target.");
  m.def(
      "linear_sweep",
      [](const py::object& center, double length, int profiles) {
        return from_poses(linear_sweep(to_pose(center, "sweep centre"), length, profiles));
      },
      py::arg("center"), py::arg("length"), py::arg("profiles"),
      "A straight striper sweep: (profiles, 4, 4) poses along center's y axis over `length`.");

  // ---- simulation ----------------------------------------------------------------------------
  py::class_<CameraMeasurement>(m, "CameraMeasurement", "A simulated depth-camera view.")
      .def_property_readonly(
          "depth", [](const CameraMeasurement& c) { return depth_to_numpy(c.image); },
          "(H, W) float32 z-depth: +inf no return, NaN invalid (closer than min_range)")
      .def_readonly("intrinsics", &CameraMeasurement::intrinsics)
      .def_property_readonly(
          "pose", [](const CameraMeasurement& c) { return from_pose(c.pose); }, "camera to world (4x4)")
      .def_readonly("max_range", &CameraMeasurement::max_range)
      .def(
          "beams", [](const CameraMeasurement& c) { return beams_to_numpy(to_beams(c)); },
          "The view's beams as (origins, ends, hits); invalid pixels dropped.");
  m.def(
      "simulate",
      [](const DepthCamera& camera, const Scene& scene, const py::object& pose, std::uint64_t seed, unsigned threads,
         std::uint64_t sensor, bool glint, double glint_angle) {
        const Pose p = to_pose(pose, "camera pose");
        const SimOptions o = sim_options(threads, glint, glint_angle);
        py::gil_scoped_release release;
        return simulate(camera, scene, p, seed, o, sensor);
      },
      py::arg("camera"), py::arg("scene"), py::arg("pose"), py::arg("seed"), py::kw_only(), py::arg("threads") = 1u,
      py::arg("sensor") = 0u, py::arg("glint") = false, py::arg("glint_angle") = kDefaultGlintAngle,
      (std::string(
           "Simulates one view of a camera at `pose` (optical frame to world, 4x4). Returns a CameraMeasurement whose\n"
           ".depth is an (H, W) float32 array. The same seed gives the same image for any thread count.\n") +
       kGlintDoc)
          .c_str());
  m.def(
      "simulate_images",
      [](const SensorRig& rig, const Scene& scene, const py::object& body, std::uint64_t seed, unsigned threads,
         bool glint, double glint_angle, const std::optional<RobotBody>& robot_body) {
        const Pose p = to_pose(body, "body pose");
        const SimOptions o = sim_options(threads, glint, glint_angle, robot_body);
        py::gil_scoped_release release;
        return simulate_images(rig, scene, p, seed, o);
      },
      py::arg("rig"), py::arg("scene"), py::arg("body"), py::arg("seed"), py::kw_only(), py::arg("threads") = 1u,
      py::arg("glint") = false, py::arg("glint_angle") = kDefaultGlintAngle, py::arg("robot_body") = py::none(),
      (std::string("One CameraMeasurement per camera of the rig with the body at `body` (stripers skipped).\n") +
       kGlintDoc + "\nrobot_" + kBodyDoc)
          .c_str());
  m.def(
      "simulate_rig",
      [](const SensorRig& rig, const Scene& scene, const py::object& bodies, std::uint64_t seed, unsigned threads,
         bool glint, double glint_angle, const std::optional<RobotBody>& robot_body) {
        auto a = py::array::ensure(bodies);
        const std::vector<Pose> path =
            a && a.ndim() == 2 ? std::vector<Pose>{to_pose(bodies, "body pose")} : to_poses(bodies, "body poses");
        const SimOptions o = sim_options(threads, glint, glint_angle, robot_body);
        std::vector<Beam> beams;
        {
          py::gil_scoped_release release;
          beams = simulate_path(rig, scene, path, seed, o);
        }
        return beams_to_numpy(beams);
      },
      py::arg("rig"), py::arg("scene"), py::arg("bodies"), py::arg("seed"), py::kw_only(), py::arg("threads") = 1u,
      py::arg("glint") = false, py::arg("glint_angle") = kDefaultGlintAngle, py::arg("robot_body") = py::none(),
      (std::string("Simulated scans of every sensor with the body at one pose (4, 4) or along a path (N, 4, 4), as\n"
                   "(origins (M, 3), ends (M, 3), hits (M,)) ready for grid.insert_beams.\n") +
       kGlintDoc + "\nrobot_" + kBodyDoc)
          .c_str());
  guarded_class<SimulatedRig>(
      m, "SimulatedRig",
      "A rig in a scene as a sensor source: rig_source(body) returns one simulated scan as\n"
      "(origins, ends, hits); scan n draws its own noise, so a seed and a pose sequence fix the beams.")
      .def(py::init([](const Scene& scene, const SensorRig& rig, std::uint64_t seed, unsigned threads, bool glint,
                       double glint_angle, const std::optional<RobotBody>& robot_body) {
             return SimulatedRig(scene, rig, seed, sim_options(threads, glint, glint_angle, robot_body));
           }),
           py::arg("scene"), py::arg("rig"), py::arg("seed"), py::kw_only(), py::arg("threads") = 1u,
           py::arg("glint") = false, py::arg("glint_angle") = kDefaultGlintAngle, py::arg("robot_body") = py::none(),
           py::keep_alive<1, 2>())
      .def("__call__", &simulated_scan, py::arg("body"))
      .def_property_readonly("scans", &SimulatedRig::scans, "scans taken so far");
}

}  // namespace intervox::python
