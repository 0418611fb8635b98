// Scene cloth and ropes: entries of "bodies" with "kind": "cloth" or "rope" (docs/scene-format.md,
// "Cloth and ropes"), built by make_cloth and make_rope (motes/cloth.h).
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string_view>
#include <utility>

#include "motes/cloth.h"
#include "scene_parts.h"

namespace motes::scene_detail {

namespace {

/// Keys of a rigid body that a cloth or rope cannot have, and why.
constexpr std::pair<std::string_view, std::string_view> kRigidOnly[] = {
    {"shape", "its particles are laid out by its \"{0}\" object"},
    {"repeat", "give each {0} an entry of its own"},
    {"rotation", "lay it out turned through the points in \"{0}\" instead"},
    {"angular_velocity", "a {0} is not a rigid body (give \"velocity\")"},
};

/// A constraint stiffness: the fraction of the error one projection removes, in (0, 1].
double read_stiffness(const Node& node) {
  const double s = node.number();
  if (!(s > 0.0 && s <= 1.0)) {
    node.fail(
        fmt::format("must be a number in (0, 1] (the fraction of a link's error one "
                    "projection removes), got {}",
                    describe(node.json())));
  }
  return s;
}

/// An array of exactly two integers, each in [lo, hi[k]].
std::array<int, 2> read_pair(const Node& node, std::int64_t lo, std::array<std::int64_t, 2> hi,
                             std::string_view what) {
  if (!node.json().is_array() || node.size() != 2) {
    node.fail(
        fmt::format("must be an array of 2 integers {}, got {}", what, describe(node.json())));
  }
  return {static_cast<int>(node.at(std::size_t{0}).integer(lo, hi[0])),
          static_cast<int>(node.at(std::size_t{1}).integer(lo, hi[1]))};
}

/// Adds a pin to `pins` (point -> JSON path of the pin that made it); fails on a duplicate.
void add_pin(const Node& pin, std::uint32_t point, std::map<std::uint32_t, std::string>& pins) {
  if (auto [it, added] = pins.emplace(point, pin.path()); !added) {
    pin.fail(fmt::format("duplicate pin: point {} is already pinned by {}", point, it->second));
  }
}

/// Unwraps make_cloth or make_rope: its message (without its "cloth: " or "rope: " prefix) follows
/// the path of the entry's "cloth" or "rope" object.
LinkedSpec take(Result<LinkedSpec> result, const Node& where, std::string_view kind) {
  if (!result) {
    std::string message = result.message();
    const std::string prefix = fmt::format("{}: ", kind);
    if (message.starts_with(prefix)) message.erase(0, prefix.size());
    where.fail(message);
  }
  return std::move(result).value();
}

/// The object's "attach" array: [{"point": ..., "body": "name"}], the point read by `point_of`.
/// A point is pinned or attached, and attached once. The body's name is checked against the
/// scene's bodies once they are all read (check_attachments).
template <typename PointOf>
void read_attachments(const Node& node, LinkedSpec& spec, PointOf point_of) {
  auto list = node.find("attach");
  if (!list) return;
  list->expect_array();
  std::map<std::uint32_t, std::string> seen;
  for (const std::uint32_t k : spec.pinned) seen.emplace(k, "\"pin\"");
  for (std::size_t k = 0; k < list->size(); ++k) {
    const Node a = list->at(k);
    a.expect_object({"point", "body"});
    const Node point = a.at("point");
    const std::uint32_t index = point_of(point);
    if (auto [it, added] = seen.emplace(index, point.path()); !added) {
      point.fail(
          fmt::format("point {} is already held by {}: a point is pinned or attached to one "
                      "body",
                      index, it->second));
    }
    spec.attached.push_back({index, a.at("body").string()});
  }
}

/// The index of the point of `c` nearest to `where` (the lowest index among equals); fails at
/// `where` when none is within one particle diameter.
std::uint32_t nearest_point(const Node& where, const LinkedSpec& c) {
  const Eigen::Vector3d x = where.vec3();
  std::uint32_t best = 0;
  double best_d = HUGE_VAL;
  for (std::size_t k = 0; k < c.points.size(); ++k) {
    const double d = (c.points[k] - x).norm();
    if (d < best_d) {
      best_d = d;
      best = static_cast<std::uint32_t>(k);
    }
  }
  if (!(best_d <= c.diameter)) {
    const Eigen::Vector3d& p = c.points[best];
    where.fail(fmt::format(
        "no vertex of the mesh within one particle diameter ({} m) of this point; the nearest, "
        "[{:.6g}, {:.6g}, {:.6g}], is {:.6g} m away",
        c.diameter, p.x(), p.y(), p.z(), best_d));
  }
  return best;
}

/// A cloth from a triangle mesh: {"mesh": file, "scale", "rotation", "position", "bend",
/// "stiffness", "bend_stiffness", "pin": [[x, y, z], ...], "attach"}; pins and attachments name
/// points in space, each taking the nearest vertex (after scale, rotation and position).
LinkedSpec read_mesh_cloth(const Node& node, double diameter, ShapeCache& cache) {
  for (const char* key : {"corner", "edge_u", "edge_v", "particles"}) {
    if (node.has(key)) {
      node.at(key).fail(
          "a cloth is a \"mesh\" or a rectangle (\"corner\", \"edge_u\", \"edge_v\", "
          "\"particles\"), not both");
    }
  }
  node.expect_object({"mesh", "scale", "rotation", "position", "bend", "stiffness",
                      "bend_stiffness", "pin", "attach"});
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  if (auto s = node.find("scale")) {
    scale = s->json().is_array() ? s->vec3(Sign::Positive)
                                 : Eigen::Vector3d::Constant(s->number(Sign::Positive));
  }
  const Eigen::Quaterniond rotation =
      node.has("rotation") ? read_rotation(node.at("rotation")) : Eigen::Quaterniond::Identity();
  const Eigen::Vector3d position =
      node.has("position") ? node.at("position").vec3() : Eigen::Vector3d::Zero();
  MeshClothOptions o;
  o.diameter = diameter;
  if (auto v = node.find("bend")) o.bend = v->boolean();
  if (auto v = node.find("stiffness")) o.stiffness = read_stiffness(*v);
  if (auto v = node.find("bend_stiffness")) o.bend_stiffness = read_stiffness(*v);
  TriangleMesh mesh = *load_mesh_once(node.at("mesh"), cache);
  for (Eigen::Vector3d& v : mesh.vertices) v = rotation * v.cwiseProduct(scale) + position;
  LinkedSpec c = take(make_mesh_cloth(mesh, o), node.at("mesh"), "cloth");
  if (auto pins = node.find("pin")) {
    pins->expect_array();
    std::map<std::uint32_t, std::string> pinned;
    for (std::size_t k = 0; k < pins->size(); ++k) {
      const Node pin = pins->at(k);
      add_pin(pin, nearest_point(pin, c), pinned);
    }
    for (const auto& entry : pinned) c.pinned.push_back(entry.first);
  }
  read_attachments(node, c, [&](const Node& point) { return nearest_point(point, c); });
  return c;
}

LinkedSpec read_cloth(const Node& node, double diameter) {
  node.expect_object({"corner", "edge_u", "edge_v", "particles", "bend", "stiffness",
                      "bend_stiffness", "pin", "attach"});
  ClothOptions o;
  o.diameter = diameter;
  o.corner = node.at("corner").vec3();
  o.edge_u = node.at("edge_u").vec3();
  o.edge_v = node.at("edge_v").vec3();
  const std::int64_t side = kLinkedMaxSide;
  const std::array<int, 2> n = read_pair(node.at("particles"), 2, {side, side}, "[nu, nv]");
  o.nu = n[0];
  o.nv = n[1];
  if (auto v = node.find("bend")) o.bend = v->boolean();
  if (auto v = node.find("stiffness")) o.stiffness = read_stiffness(*v);
  if (auto v = node.find("bend_stiffness")) o.bend_stiffness = read_stiffness(*v);
  LinkedSpec c = take(make_cloth(o), node, "cloth");
  if (auto pins = node.find("pin")) {
    pins->expect_array();
    std::map<std::uint32_t, std::string> pinned;
    for (std::size_t k = 0; k < pins->size(); ++k) {
      const Node pin = pins->at(k);
      const std::array<int, 2> ij = read_pair(pin, 0, {o.nu - 1, o.nv - 1}, "[i, j]");
      add_pin(pin, cloth_index(o, ij[0], ij[1]), pinned);
    }
    for (const auto& entry : pinned) c.pinned.push_back(entry.first);
  }
  read_attachments(node, c, [&](const Node& point) {
    const std::array<int, 2> ij = read_pair(point, 0, {o.nu - 1, o.nv - 1}, "[i, j]");
    return cloth_index(o, ij[0], ij[1]);
  });
  return c;
}

LinkedSpec read_rope(const Node& node, double diameter) {
  node.expect_object(
      {"from", "to", "path", "particles", "bend", "stiffness", "bend_stiffness", "pin", "attach"});
  RopeOptions o;
  o.diameter = diameter;
  if (auto path = node.find("path")) {
    for (const char* key : {"from", "to"}) {
      if (node.has(key)) node.at(key).fail("give either \"path\" or \"from\" and \"to\", not both");
    }
    path->expect_array();
    if (path->size() < 2) path->fail("must hold at least two points [x, y, z]");
    for (std::size_t k = 0; k < path->size(); ++k) o.path.push_back(path->at(k).vec3());
  } else {
    o.from = node.at("from").vec3();
    o.to = node.at("to").vec3();
  }
  o.count = static_cast<int>(node.at("particles").integer(2, kLinkedMaxSide));
  if (auto v = node.find("bend")) o.bend = v->boolean();
  if (auto v = node.find("stiffness")) o.stiffness = read_stiffness(*v);
  if (auto v = node.find("bend_stiffness")) o.bend_stiffness = read_stiffness(*v);
  LinkedSpec r = take(make_rope(o), node, "rope");
  if (auto pins = node.find("pin")) {
    pins->expect_array();
    std::map<std::uint32_t, std::string> pinned;
    for (std::size_t k = 0; k < pins->size(); ++k) {
      const Node pin = pins->at(k);
      const std::int64_t i = pin.integer(-o.count, o.count - 1);  // -1: the last
      add_pin(pin, static_cast<std::uint32_t>(i < 0 ? i + o.count : i), pinned);
    }
    for (const auto& entry : pinned) r.pinned.push_back(entry.first);
  }
  read_attachments(node, r, [&](const Node& point) {
    const std::int64_t i = point.integer(-o.count, o.count - 1);  // -1: the last
    return static_cast<std::uint32_t>(i < 0 ? i + o.count : i);
  });
  return r;
}

}  // namespace

bool is_linked(const Node& entry) {
  const Json& json = entry.json();
  if (!json.is_object()) return false;
  const auto kind = json.find("kind");
  return kind != json.end() && kind->is_string() && (*kind == "cloth" || *kind == "rope");
}

LinkedSpec read_linked(const Node& entry, std::size_t index, ShapeCache& cache,
                       const Scene& scene) {
  const std::string kind = entry.at("kind").string();
  if (scene.linked.size() >= kLinkedMaxObjects) {
    entry.fail(fmt::format("more than {} cloth and rope objects in one scene", kLinkedMaxObjects));
  }
  for (const auto& [key, why] : kRigidOnly) {
    if (entry.has(key)) {
      entry.at(key).fail(
          fmt::format("not allowed on a {}: {}", kind, fmt::format(fmt::runtime(why), kind)));
    }
  }
  entry.expect_object({"name", "kind", "material", "diameter", kind, "velocity", "color"});
  const double diameter =
      entry.has("diameter") ? entry.at("diameter").number(Sign::Positive) : cache.default_diameter;
  const Node shape = entry.at(kind);
  LinkedSpec spec = kind == "rope"      ? read_rope(shape, diameter)
                    : shape.has("mesh") ? read_mesh_cloth(shape, diameter, cache)
                                        : read_cloth(shape, diameter);
  for (const Eigen::Vector3d& p : spec.points) {
    if (!(p.cwiseAbs().maxCoeff() <= static_cast<double>(std::numeric_limits<float>::max()))) {
      shape.fail("a particle lands outside the float range");
    }
  }
  spec.name = entry.has("name") ? entry.at("name").string() : fmt::format("{}{}", kind, index);
  spec.material = entry.has("material") ? find_material(entry.at("material"), scene.materials) : 0;
  if (auto v = entry.find("velocity")) spec.velocity = v->vec3();
  if (auto color = entry.find("color")) spec.color = read_color(*color);
  return spec;
}

}  // namespace motes::scene_detail
