#pragma once
/// \file
/// The run file of the viewer: a ViewScene (trajectory, views, rig, highlighted regions) as JSON.
/// Needs nlohmann-json (Debian nlohmann-json3-dev, header-only). The format (docs/viewing.md):
/// \code{.json}
/// {
///   "trajectory": [ {"position": [x, y, z], "quaternion": [w, x, y, z]}, [x, y, z], ... ],
///   "scans":      [ same pose forms ],
///   "rig":        "mobile_base" | "arm" | "none",
///   "view_range": 0.5,
///   "regions":    [ {"min": [x, y, z], "max": [x, y, z], "label": "conflict 1"} ]
/// }
/// \endcode
/// Every member is optional. A pose is an object with "position" (metres, world frame) and an
/// optional unit "quaternion" (w, x, y, z; default identity; normalised when read), or just a
/// position array.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/io/detail/binary.hpp>
#include <intervox/io/detail/text.hpp>
#include <intervox/io/load_budget.hpp>
#include <intervox/io/text_file.hpp>
#include <intervox/view/html_view.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

namespace intervox {

namespace detail {

inline Point3 json_point(const nlohmann::json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) throw IoError(where + ": expected an array of 3 numbers");
  Point3 p;
  for (int i = 0; i < 3; ++i) {
    const auto& e = j[static_cast<std::size_t>(i)];
    if (!e.is_number() || !std::isfinite(e.get<double>()))
      throw IoError(where + ": expected an array of 3 finite numbers");
    p[i] = e.get<double>();
  }
  return p;
}

inline Pose json_pose(const nlohmann::json& j, const std::string& where) {
  Pose pose = Pose::Identity();
  if (j.is_array()) {
    pose.translation() = json_point(j, where);
    return pose;
  }
  if (!j.is_object() || !j.contains("position"))
    throw IoError(where + ": expected a pose {\"position\": [x, y, z], ...}");
  pose.translation() = json_point(j["position"], where + ".position");
  if (j.contains("quaternion")) {
    const auto& q = j["quaternion"];
    if (!q.is_array() || q.size() != 4) throw IoError(where + ".quaternion: expected [w, x, y, z]");
    double v[4];
    for (std::size_t i = 0; i < 4; ++i) {
      if (!q[i].is_number() || !std::isfinite(q[i].get<double>()))
        throw IoError(where + ".quaternion: expected 4 finite numbers");
      v[i] = q[i].get<double>();
    }
    Eigen::Quaterniond quat(v[0], v[1], v[2], v[3]);
    if (!(quat.norm() > 1e-9)) throw IoError(where + ".quaternion: zero quaternion");
    pose.linear() = quat.normalized().toRotationMatrix();
  }
  return pose;
}

inline nlohmann::json pose_json(const Pose& p) {
  const Eigen::Quaterniond q(p.rotation());
  const Point3 t = p.translation();
  return {{"position", {t.x(), t.y(), t.z()}}, {"quaternion", {q.w(), q.x(), q.y(), q.z()}}};
}

}  // namespace detail

/// Parses a run file's text. \p source names it in messages.
/// \throws IoError naming the source and the member for malformed JSON or members of the wrong form.
/// Thread safety: reentrant.
inline ViewScene view_scene_from_json(const std::string& text, const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(source + ": not valid JSON: " + detail::quote_bytes(e.what(), 400));
  }
  if (!j.is_object()) throw IoError(source + ": expected a JSON object");
  ViewScene s;
  auto poses = [&](const char* name, std::vector<Pose>& out) {
    if (!j.contains(name)) return;
    if (!j[name].is_array()) throw IoError(source + ": " + name + ": expected an array of poses");
    for (std::size_t i = 0; i < j[name].size(); ++i)
      out.push_back(detail::json_pose(j[name][i], source + ": " + name + "[" + std::to_string(i) + "]"));
  };
  poses("trajectory", s.trajectory);
  poses("scans", s.scans);
  if (j.contains("rig")) {
    const auto& r = j["rig"];
    if (r == "mobile_base")
      s.rig = SensorRig::mobile_base();
    else if (r == "arm")
      s.rig = SensorRig::arm();
    else if (r != "none")
      throw IoError(source + ": rig: expected \"mobile_base\", \"arm\" or \"none\"");
  }
  if (j.contains("view_range")) {
    const auto& v = j["view_range"];
    if (!v.is_number() || !(v.get<double>() > 0) || !std::isfinite(v.get<double>()))
      throw IoError(source + ": view_range: expected a positive number");
    s.view_range = v.get<double>();
  }
  if (j.contains("regions")) {
    if (!j["regions"].is_array()) throw IoError(source + ": regions: expected an array");
    for (std::size_t i = 0; i < j["regions"].size(); ++i) {
      const auto& r = j["regions"][i];
      const std::string where = source + ": regions[" + std::to_string(i) + "]";
      if (!r.is_object() || !r.contains("min") || !r.contains("max"))
        throw IoError(where + ": expected {\"min\": [..], \"max\": [..]}");
      ViewRegion region{{detail::json_point(r["min"], where + ".min"), detail::json_point(r["max"], where + ".max")},
                        {}};
      if (!region.box.valid()) throw IoError(where + ": min must not exceed max");
      if (r.contains("label")) {
        if (!r["label"].is_string()) throw IoError(where + ".label: expected a string");
        region.label = r["label"].get<std::string>();
      }
      s.regions.push_back(std::move(region));
    }
  }
  return s;
}

/// Largest run file read_view_scene reads: 256 MiB (a trajectory of millions of poses).
inline constexpr std::uint64_t kMaxViewSceneBytes = std::uint64_t{1} << 28;

/// Reads a run file (at most kMaxViewSceneBytes; it must be a regular file).
/// \throws IoError if it cannot be read, is not a regular file (a directory, /dev/zero, a FIFO), is
///   larger than the limit, or is malformed (naming the file); never std::bad_alloc.
/// Thread safety: reentrant.
inline ViewScene read_view_scene(const std::string& path) {
  const std::string where = "run file '" + path + "'";
  return detail::guard_allocation(where, [&] {
    std::string text;
    try {
      text = detail::read_file_bytes(path, kMaxViewSceneBytes);
    } catch (const IoError& e) {
      throw IoError("cannot open run file '" + path + "': " + e.what());
    }
    return view_scene_from_json(text, path);
  });
}

/// The run file's JSON for \p scene; \p rig_name ("mobile_base", "arm" or "none") names the rig
/// preset the reader rebuilds (a rig is not serialised sensor by sensor).
/// \throws InvalidArgument for another rig name.
/// Thread safety: reentrant.
inline std::string view_scene_to_json(const ViewScene& scene, const std::string& rig_name = "none") {
  if (rig_name != "mobile_base" && rig_name != "arm" && rig_name != "none")
    ParamCheck("intervox::view_scene_to_json").fail("rig must be \"mobile_base\", \"arm\" or \"none\"");
  nlohmann::json j;
  j["trajectory"] = nlohmann::json::array();
  for (const Pose& p : scene.trajectory) j["trajectory"].push_back(detail::pose_json(p));
  j["scans"] = nlohmann::json::array();
  for (const Pose& p : scene.scans) j["scans"].push_back(detail::pose_json(p));
  j["rig"] = rig_name;
  j["view_range"] = scene.view_range;
  j["regions"] = nlohmann::json::array();
  for (const ViewRegion& r : scene.regions) {
    j["regions"].push_back({{"min", {r.box.min.x(), r.box.min.y(), r.box.min.z()}},
                            {"max", {r.box.max.x(), r.box.max.y(), r.box.max.z()}},
                            {"label", r.label}});
  }
  return j.dump(1);
}

}  // namespace intervox
