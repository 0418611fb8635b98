// Scene bodies: the "bodies" array, with repeats expanded into named copies sharing one shape
// (cloth and ropes are read in scene_linked.cpp).
#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <map>

#include "scene_parts.h"

namespace motes::scene_detail {

namespace {

/// Positions and orientations of the copies of a repeated body.
struct Repeat {
  Eigen::Matrix<std::int64_t, 3, 1> grid{1, 1, 1};  ///< copies along x, y, z
  Eigen::Vector3d offset_x = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset_y = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset_z = Eigen::Vector3d::Zero();
  Eigen::Quaterniond step = Eigen::Quaterniond::Identity();  ///< extra rotation per copy
  bool repeated = false;

  [[nodiscard]] std::int64_t copies() const { return grid[0] * grid[1] * grid[2]; }
};

Repeat read_repeat(const Node& node, std::int64_t max_copies) {
  node.expect_object({"count", "offset", "grid", "spacing", "rotation"});
  Repeat r;
  r.repeated = true;
  if (node.has("count") == node.has("grid")) {
    node.fail("give either \"count\" with \"offset\", or \"grid\" with \"spacing\"");
  }
  if (auto count = node.find("count")) {
    if (node.has("spacing"))
      node.at("spacing").fail("\"spacing\" goes with \"grid\", not \"count\"");
    r.grid[0] = count->integer(1, max_copies);
    r.offset_x = node.at("offset").vec3();
  } else {
    if (node.has("offset")) node.at("offset").fail("\"offset\" goes with \"count\", not \"grid\"");
    const Node grid = node.at("grid");
    r.grid = grid.int3(1, max_copies);
    const double total = static_cast<double>(r.grid[0]) * static_cast<double>(r.grid[1]) *
                         static_cast<double>(r.grid[2]);
    if (total > static_cast<double>(max_copies)) {
      grid.fail(
          fmt::format("{} copies is more than settings.max_particles ({})", total, max_copies));
    }
    const Eigen::Vector3d spacing = node.at("spacing").vec3();
    r.offset_x = Eigen::Vector3d(spacing.x(), 0.0, 0.0);
    r.offset_y = Eigen::Vector3d(0.0, spacing.y(), 0.0);
    r.offset_z = Eigen::Vector3d(0.0, 0.0, spacing.z());
  }
  if (auto rot = node.find("rotation")) r.step = read_rotation(*rot);
  return r;
}

/// The "soft" object of a soft body (docs/scene-format.md, "Soft bodies").
SoftSpec read_soft(const Node& node) {
  node.expect_object({"stiffness", "frequency", "damping", "mode", "beta", "clusters"});
  SoftSpec soft;
  if (node.has("stiffness") && node.has("frequency")) {
    node.at("frequency").fail("give \"stiffness\" (per substep) or \"frequency\" (Hz), not both");
  }
  if (auto a = node.find("stiffness")) {
    soft.stiffness = a->number(Sign::Positive);
    if (soft.stiffness > 1.0) a->fail("the stiffness is a fraction per substep, in (0, 1]");
  }
  if (auto f = node.find("frequency")) soft.frequency = f->number(Sign::Positive);
  if (auto d = node.find("damping")) soft.damping = d->number(Sign::NonNegative);
  if (auto m = node.find("mode")) {
    const std::string mode = m->string();
    if (mode == "rigid") {
      soft.mode = SoftMode::Rigid;
    } else if (mode == "linear") {
      soft.mode = SoftMode::Linear;
    } else if (mode == "quadratic") {
      soft.mode = SoftMode::Quadratic;
    } else {
      m->fail(fmt::format("must be \"rigid\", \"linear\" or \"quadratic\", got \"{}\"", mode));
    }
  }
  if (auto b = node.find("beta")) {
    soft.beta = b->number(Sign::NonNegative);
    if (soft.beta > 1.0) b->fail("beta blends the fitted deformation in: it must be in [0, 1]");
    if (soft.mode == SoftMode::Rigid && soft.beta > 0.0) {
      b->fail("beta needs \"mode\": \"linear\" or \"quadratic\" (a rigid goal has no fit)");
    }
  }
  if (auto c = node.find("clusters")) {
    const auto cells = c->int3(1, 64);
    soft.clusters = {static_cast<int>(cells[0]), static_cast<int>(cells[1]),
                     static_cast<int>(cells[2])};
  }
  return soft;
}

Eigen::Vector3d read_vector_or_zero(const Node& body, std::string_view key) {
  if (auto v = body.find(key)) return v->vec3();
  return Eigen::Vector3d::Zero();
}

}  // namespace

Eigen::Vector3d read_color(const Node& node) {
  const std::string expected = "must be a colour: [r, g, b] with each from 0 to 1, or \"#rrggbb\"";
  if (node.json().is_string()) {
    const std::string text = node.json().get<std::string>();
    const auto hex = [](char c) {
      if (c >= '0' && c <= '9') return c - '0';
      if (c >= 'a' && c <= 'f') return c - 'a' + 10;
      if (c >= 'A' && c <= 'F') return c - 'A' + 10;
      return -1;
    };
    Eigen::Vector3d rgb;
    bool ok = text.size() == 7 && text[0] == '#';
    for (int i = 0; ok && i < 3; ++i) {
      const int hi = hex(text[static_cast<std::size_t>(1 + 2 * i)]);
      const int lo = hex(text[static_cast<std::size_t>(2 + 2 * i)]);
      ok = hi >= 0 && lo >= 0;
      rgb[i] = (16 * hi + lo) / 255.0;
    }
    if (!ok) node.fail(fmt::format("{}, got {}", expected, scene_detail::describe(node.json())));
    return rgb;
  }
  if (!node.json().is_array() || node.size() != 3) {
    node.fail(fmt::format("{}, got {}", expected, scene_detail::describe(node.json())));
  }
  Eigen::Vector3d rgb;
  for (std::size_t i = 0; i < 3; ++i) {
    const Node c = node.at(i);
    rgb[static_cast<int>(i)] = c.number(Sign::NonNegative);
    if (rgb[static_cast<int>(i)] > 1.0) {
      c.fail(fmt::format("must be from 0 to 1 (a colour component), got {}",
                         scene_detail::describe(c.json())));
    }
  }
  return rgb;
}

int find_material(const Node& where, const std::vector<Material>& materials) {
  const std::string name = where.string();
  std::vector<std::string> names;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == name) return static_cast<int>(i);
    names.push_back(materials[i].name);
  }
  where.fail(fmt::format("unknown material \"{}\" (defined: {})", name, fmt::join(names, ", ")));
}

void read_bodies(const Node& bodies, ShapeCache& cache, Scene& scene,
                 std::vector<BodyEntry>& entries) {
  bodies.expect_array();
  if (bodies.size() == 0) bodies.fail("a scene needs at least one body");
  std::map<std::string, std::string> names;                  // body name -> JSON path that made it
  std::vector<std::pair<std::size_t, Node>> linked_entries;  // objects with attachments
  std::uint64_t particles = 0;
  // Counts before expanding, so an oversized scene is refused before it is built.
  const auto count = [&](const Node& body, std::uint64_t more) {
    particles += more;
    if (particles > static_cast<std::uint64_t>(cache.max_particles)) {
      body.fail(
          fmt::format("the scene would have {} particles, more than settings.max_particles "
                      "({})",
                      particles, cache.max_particles));
    }
  };
  const auto add_name = [&](const Node& body, const std::string& name, const std::string& where) {
    if (auto [it, added] = names.emplace(name, where); !added) {
      const Node name_node = body.has("name") ? body.at("name") : body;
      name_node.fail(fmt::format("duplicate body name \"{}\" (also made by {})", name, it->second));
    }
  };
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Node body = bodies.at(i);
    if (is_linked(body)) {
      LinkedSpec spec = read_linked(body, i, cache, scene);
      check_initial_speed(
          body,
          fmt::format("{} \"{}\"", spec.kind == LinkedKind::Cloth ? "cloth" : "rope", spec.name),
          spec.velocity, Eigen::Vector3d::Zero(), 0.0, spec.diameter, scene.settings);
      count(body, spec.points.size());
      add_name(body, spec.name, body.path());
      if (!spec.attached.empty()) linked_entries.emplace_back(scene.linked.size(), body);
      scene.linked.push_back(std::move(spec));
      continue;
    }
    if (is_fluid(body)) {
      FluidSpec spec = read_fluid(body, i, cache, scene);
      check_initial_speed(body, fmt::format("fluid \"{}\"", spec.name), spec.velocity,
                          Eigen::Vector3d::Zero(), 0.0, spec.diameter, scene.settings);
      count(body, spec.points.size());
      add_name(body, spec.name, body.path());
      scene.fluids.push_back(std::move(spec));
      continue;
    }
    if (auto fluid = body.find("fluid")) fluid->fail("\"fluid\" settings need \"kind\": \"fluid\"");
    body.expect_object({"name", "kind", "shape", "material", "position", "rotation", "velocity",
                        "angular_velocity", "repeat", "color", "soft"});
    BodySpec spec;
    spec.name = body.has("name") ? body.at("name").string() : fmt::format("body{}", i);
    if (auto kind = body.find("kind")) {
      const std::string k = kind->string();
      if (k == "static") {
        spec.kind = BodyKind::Static;
      } else if (k == "soft") {
        spec.soft = SoftSpec{};
      } else if (k != "dynamic") {
        kind->fail(fmt::format(
            "must be \"dynamic\", \"static\", \"soft\", \"cloth\", \"rope\" or \"fluid\", got "
            "\"{}\"",
            k));
      }
    }
    if (auto soft = body.find("soft")) {
      if (!spec.soft) soft->fail("\"soft\" settings need \"kind\": \"soft\"");
      spec.soft = read_soft(*soft);
    }
    if (auto color = body.find("color")) spec.color = read_color(*color);
    spec.material = body.has("material") ? find_material(body.at("material"), scene.materials) : 0;
    spec.position = read_vector_or_zero(body, "position");
    if (auto rot = body.find("rotation")) spec.rotation = read_rotation(*rot);
    spec.velocity = read_vector_or_zero(body, "velocity");
    spec.angular_velocity = read_vector_or_zero(body, "angular_velocity");
    if (spec.kind == BodyKind::Static) {
      for (const char* key : {"velocity", "angular_velocity"}) {
        if (body.has(key) && !body.at(key).vec3().isZero(0.0)) {
          body.at(key).fail("a static body cannot move (make it \"dynamic\" or remove this)");
        }
      }
    }
    const std::int64_t max_copies = cache.max_particles;
    const Repeat repeat =
        body.has("repeat") ? read_repeat(body.at("repeat"), max_copies) : Repeat{};
    spec.shape = read_shape(body.at("shape"), cache);

    const std::uint64_t copies = static_cast<std::uint64_t>(repeat.copies());
    count(body, copies * spec.shape->points.size());
    if (spec.kind == BodyKind::Dynamic) {
      // Its fastest particle at the start: |v| + |w| x the farthest particle centre from the
      // centre of mass (the particles are equal: the centroid).
      double reach = 0.0;
      if (!spec.angular_velocity.isZero(0.0)) {
        Eigen::Vector3d centre = Eigen::Vector3d::Zero();
        for (const Eigen::Vector3f& p : spec.shape->points) centre += p.cast<double>();
        centre /= static_cast<double>(spec.shape->points.size());
        for (const Eigen::Vector3f& p : spec.shape->points) {
          reach = std::max(reach, (p.cast<double>() - centre).norm());
        }
      }
      check_initial_speed(body, fmt::format("body \"{}\"", spec.name), spec.velocity,
                          spec.angular_velocity, reach, spec.shape->diameter, scene.settings);
    }

    entries.push_back(BodyEntry{scene.bodies.size(), copies, body.path()});
    Eigen::Quaterniond step_rotation = Eigen::Quaterniond::Identity();
    std::int64_t index = 0;
    for (std::int64_t z = 0; z < repeat.grid[2]; ++z) {
      for (std::int64_t y = 0; y < repeat.grid[1]; ++y) {
        for (std::int64_t x = 0; x < repeat.grid[0]; ++x, ++index) {
          BodySpec copy = spec;
          if (repeat.repeated) copy.name = fmt::format("{}[{}]", spec.name, index);
          copy.position = spec.position + static_cast<double>(x) * repeat.offset_x +
                          static_cast<double>(y) * repeat.offset_y +
                          static_cast<double>(z) * repeat.offset_z;
          if (!(copy.position.cwiseAbs().maxCoeff() <=
                static_cast<double>(std::numeric_limits<float>::max()))) {
            body.at("repeat").fail(fmt::format("copy {} lands outside the float range", index));
          }
          copy.rotation = (step_rotation * spec.rotation).normalized();
          step_rotation = (repeat.step * step_rotation).normalized();
          add_name(body, copy.name, repeat.repeated ? body.path() + "/repeat" : body.path());
          scene.bodies.push_back(std::move(copy));
        }
      }
    }
  }
  // Attachments name bodies anywhere in the array: checked once every body is known.
  for (const auto& [object, entry] : linked_entries) {
    const LinkedSpec& spec = scene.linked[object];
    const Node list = entry.at(spec.kind == LinkedKind::Cloth ? "cloth" : "rope").at("attach");
    for (std::size_t k = 0; k < spec.attached.size(); ++k) {
      const Node name = list.at(k).at("body");
      const std::string& wanted = spec.attached[k].body;
      const auto it = std::find_if(scene.bodies.begin(), scene.bodies.end(),
                                   [&](const BodySpec& b) { return b.name == wanted; });
      if (it == scene.bodies.end()) {
        const bool linked = std::any_of(scene.linked.begin(), scene.linked.end(),
                                        [&](const LinkedSpec& l) { return l.name == wanted; });
        name.fail(linked ? fmt::format("\"{}\" is a cloth or rope: attach to a rigid or static "
                                       "body (link two cloths by one object instead)",
                                       wanted)
                         : fmt::format("no body named \"{}\" in this scene", wanted));
      }
      if (it->soft) {
        name.fail(
            fmt::format("\"{}\" is a soft body: cloth and ropes attach to rigid or static "
                        "bodies",
                        wanted));
      }
    }
  }
}

}  // namespace motes::scene_detail
