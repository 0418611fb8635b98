// Scene shapes: a "shape" object to a ParticleSet through the shapes API (motes/shapes.h).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <system_error>

#include "scene_parts.h"

namespace motes::scene_detail {

namespace {

namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;

/// Unwraps a shapes-API result; its message (which names the reason) follows the JSON path.
std::shared_ptr<const ParticleSet> take(Result<ParticleSet> result, const Node& where) {
  if (!result) where.fail(result.message());
  return std::make_shared<const ParticleSet>(std::move(result).value());
}

/// Refuses, before building, a shape that would clearly exceed settings.max_particles (the exact
/// count is checked again on the whole scene once it is built).
void check_estimate(const Node& where, double estimate, const ShapeCache& cache) {
  // Estimates are volumes over d^3: a lattice may hold somewhat more near the surface, so only
  // twice the limit is refused here, before any memory is spent.
  if (estimate > 2.0 * static_cast<double>(cache.max_particles)) {
    where.fail(
        fmt::format("would make about {:.3g} particles, more than settings.max_particles "
                    "({}); use a larger particle_diameter",
                    estimate, cache.max_particles));
  }
}

double read_diameter(const Node& shape, const ShapeCache& cache) {
  if (auto d = shape.find("particle_diameter")) return d->number(Sign::Positive);
  return cache.default_diameter;
}

/// Volume enclosed by a closed, consistently oriented mesh (divergence theorem).
double mesh_volume(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<std::size_t>(t[2])];
    six_v += a.dot(b.cross(c));
  }
  return std::abs(six_v) / 6.0;
}

std::shared_ptr<const ParticleSet> read_mesh(const Node& shape, ShapeCache& cache) {
  shape.expect_object({"type", "file", "scale", "particle_diameter", "particle_count"});
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  if (auto s = shape.find("scale")) {
    scale = s->json().is_array() ? s->vec3(Sign::Positive)
                                 : Eigen::Vector3d::Constant(s->number(Sign::Positive));
  }
  if (shape.has("particle_diameter") && shape.has("particle_count")) {
    shape.fail("give either \"particle_diameter\" or \"particle_count\", not both");
  }
  VoxelizeOptions options;
  if (auto n = shape.find("particle_count")) {
    options.target_count = static_cast<std::size_t>(n->integer(1, cache.max_particles));
  } else {
    options.diameter = read_diameter(shape, cache);
  }

  const std::shared_ptr<const TriangleMesh> loaded = load_mesh_once(shape.at("file"), cache);
  TriangleMesh mesh = *loaded;
  for (Eigen::Vector3d& v : mesh.vertices) v = v.cwiseProduct(scale);
  if (options.diameter > 0.0) {
    check_estimate(shape, mesh_volume(mesh) / std::pow(options.diameter, 3.0), cache);
  }
  return take(voxelize(mesh, options), shape);
}

}  // namespace

std::shared_ptr<const TriangleMesh> load_mesh_once(const Node& file, ShapeCache& cache) {
  const std::string name = file.string();
  fs::path path(name);
  if (path.is_relative() && !cache.base_dir.empty()) path = fs::path(cache.base_dir) / path;
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(path, ec);
  const std::string key = ec ? path.lexically_normal().string() : resolved.string();
  if (auto it = cache.meshes.find(key); it != cache.meshes.end()) return it->second;

  if (!fs::exists(path, ec)) {
    file.fail(fmt::format("cannot open mesh \"{}\": no such file", path.string()));
  }
  if (fs::is_directory(path, ec)) {
    file.fail(fmt::format("cannot open mesh \"{}\": is a directory", path.string()));
  }
  Result<TriangleMesh> mesh = load_mesh(path.string());
  if (!mesh) file.fail(mesh.message());
  auto shared = std::make_shared<const TriangleMesh>(std::move(mesh).value());
  cache.meshes.emplace(key, shared);
  return shared;
}

Eigen::Quaterniond read_rotation(const Node& rotation) {
  rotation.expect_object({"axis", "degrees"});
  const Node axis_node = rotation.at("axis");
  const Eigen::Vector3d axis = axis_node.vec3();
  const double norm = axis.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) {
    axis_node.fail("must be a non-zero vector");
  }
  const double degrees = rotation.at("degrees").number();
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kPi / 180.0, axis / norm));
}

std::shared_ptr<const ParticleSet> read_shape(const Node& shape, ShapeCache& cache) {
  if (!shape.json().is_object()) {
    shape.fail(fmt::format("must be an object with a \"type\", got {}", describe(shape.json())));
  }
  const Node type_node = shape.at("type");
  const std::string type = type_node.string();

  // Identical descriptions (with the same default diameter) give one shared particle set.
  const std::string key = shape.json().dump() + fmt::format("|{}", cache.default_diameter);
  auto build = [&]() -> std::shared_ptr<const ParticleSet> {
    if (type == "box") {
      shape.expect_object({"type", "size", "particles", "particle_diameter"});
      const double d = read_diameter(shape, cache);
      if (shape.has("size") == shape.has("particles")) {
        shape.fail("a box needs exactly one of \"size\" (metres) or \"particles\" ([nx, ny, nz])");
      }
      if (auto counts = shape.find("particles")) {
        const auto n = counts->int3(1, cache.max_particles);
        const double total =
            static_cast<double>(n[0]) * static_cast<double>(n[1]) * static_cast<double>(n[2]);
        if (total > static_cast<double>(cache.max_particles)) {
          counts->fail(
              fmt::format("{} x {} x {} particles is more than settings.max_particles ({})", n[0],
                          n[1], n[2], cache.max_particles));
        }
        return take(box_lattice(n.cast<int>(), d), shape);
      }
      const Node size_node = shape.at("size");
      const Eigen::Vector3d size = size_node.vec3(Sign::Positive);
      check_estimate(size_node, size.prod() / (d * d * d), cache);
      return take(box_particles(size, d), shape);
    }
    if (type == "sphere") {
      shape.expect_object({"type", "radius", "particle_diameter"});
      const double d = read_diameter(shape, cache);
      const double r = shape.at("radius").number(Sign::Positive);
      check_estimate(shape, 4.0 / 3.0 * kPi * std::pow(r / d, 3.0), cache);
      return take(sphere_particles(r, d), shape);
    }
    if (type == "cylinder" || type == "capsule") {
      shape.expect_object({"type", "radius", "height", "particle_diameter"});
      const double d = read_diameter(shape, cache);
      const double r = shape.at("radius").number(Sign::Positive);
      const double h = shape.at("height").number(Sign::Positive);
      const double caps = type == "capsule" ? 4.0 / 3.0 * kPi * r * r * r : 0.0;
      check_estimate(shape, (kPi * r * r * h + caps) / (d * d * d), cache);
      return take(type == "capsule" ? capsule_particles(r, h, d) : cylinder_particles(r, h, d),
                  shape);
    }
    if (type == "particle") {
      shape.expect_object({"type", "particle_diameter"});
      // One sphere: a 1 x 1 x 1 lattice.
      return take(box_lattice(Eigen::Vector3i::Ones(), read_diameter(shape, cache)), shape);
    }
    if (type == "mesh") return read_mesh(shape, cache);
    type_node.fail(fmt::format(
        "unknown shape type \"{}\" (allowed: box, sphere, cylinder, capsule, particle, mesh)",
        type));
  };

  if (auto it = cache.shapes.find(key); it != cache.shapes.end()) return it->second;
  std::shared_ptr<const ParticleSet> set = build();
  if (set->points.empty()) shape.fail("the shape has no particles");
  cache.shapes.emplace(key, set);
  return set;
}

}  // namespace motes::scene_detail
