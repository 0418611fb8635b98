// Fluids in a scene file: an entry of "bodies" with "kind": "fluid" (issue 29; docs/fluids.md,
// docs/scene-format.md "Fluids"): a box, a sphere or a mesh's volume filled with particles on a
// cubic lattice at the rest spacing (fluid_rest_spacing: the spacing at which the kernel's sum is
// the rest density, so a fill starts at rest).
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "motes/fluid.h"
#include "motes/shapes.h"
#include "scene_parts.h"

namespace motes::scene_detail {

namespace {

/// Lattice steps of spacing d that fit in a length (a particle's extent within it); the epsilon
/// keeps a box of exactly n diameters at n.
std::int64_t steps_within(double length, double d) {
  return static_cast<std::int64_t>(std::floor(length / d + 1e-9));
}

void check_count(const Node& where, double count, const ShapeCache& cache) {
  if (count > static_cast<double>(cache.max_particles)) {
    where.fail(
        fmt::format("the fluid would have {} particles, more than settings.max_particles ({})",
                    count, cache.max_particles));
  }
}

/// A box [min, max]: the lattice of spacing s (fluid_rest_spacing) whose first particle touches
/// min on every axis, every particle lying inside the box.
std::vector<Eigen::Vector3d> fill_box(const Node& fluid, double d, const ShapeCache& cache) {
  const double s = fluid_rest_spacing(d);
  const Eigen::Vector3d lo = fluid.at("min").vec3();
  const Node max_node = fluid.at("max");
  const Eigen::Vector3d hi = max_node.vec3();
  Eigen::Matrix<std::int64_t, 3, 1> n;
  for (int i = 0; i < 3; ++i) {
    const Node axis = max_node.at(static_cast<std::size_t>(i));
    if (!(hi[i] > lo[i])) {
      axis.fail(fmt::format("must be greater than min[{}] ({} <= {})", i, hi[i], lo[i]));
    }
    if (hi[i] - lo[i] < d * (1.0 - 1e-9)) {
      axis.fail(
          fmt::format("the box is {} m wide on this axis, less than one particle diameter "
                      "({} m)",
                      hi[i] - lo[i], d));
    }
    n[i] = 1 + steps_within(std::max(0.0, hi[i] - lo[i] - d), s);
  }
  check_count(fluid,
              static_cast<double>(n[0]) * static_cast<double>(n[1]) * static_cast<double>(n[2]),
              cache);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(n[0] * n[1] * n[2]));
  for (std::int64_t z = 0; z < n[2]; ++z) {
    for (std::int64_t y = 0; y < n[1]; ++y) {
      for (std::int64_t x = 0; x < n[0]; ++x) {
        points.push_back(lo + Eigen::Vector3d::Constant(0.5 * d) +
                         s * Eigen::Vector3d(static_cast<double>(x), static_cast<double>(y),
                                             static_cast<double>(z)));
      }
    }
  }
  return points;
}

/// A sphere: the lattice of spacing s centred on its centre, every particle lying inside it.
std::vector<Eigen::Vector3d> fill_sphere(const Node& fluid, double d, const ShapeCache& cache) {
  const double s = fluid_rest_spacing(d);
  const Eigen::Vector3d centre = fluid.at("center").vec3();
  const Node radius_node = fluid.at("radius");
  const double radius = radius_node.number(Sign::Positive);
  const double reach = radius - 0.5 * d;
  if (!(reach >= 0.0)) {
    radius_node.fail(
        fmt::format("a sphere of radius {} m holds no particle of diameter {} m", radius, d));
  }
  const std::int64_t k = steps_within(reach, s);
  const double side = static_cast<double>(2 * k + 1);
  check_count(fluid, side * side * side * std::acos(-1.0) / 6.0, cache);
  std::vector<Eigen::Vector3d> points;
  for (std::int64_t z = -k; z <= k; ++z) {
    for (std::int64_t y = -k; y <= k; ++y) {
      for (std::int64_t x = -k; x <= k; ++x) {
        const Eigen::Vector3d offset =
            s *
            Eigen::Vector3d(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z));
        if (offset.norm() <= reach * (1.0 + 1e-12)) points.push_back(centre + offset);
      }
    }
  }
  return points;
}

/// A mesh's volume: the voxelizer's lattice of spacing s (fluid_rest_spacing) inside the mesh
/// (scaled by "scale", a number or one per axis), in the mesh's own coordinates moved by "position"
/// (no rotation: rotate the mesh file). A closed mesh is filled by its crossings, an open one by
/// its winding number, as a body's mesh shape is (docs/scene-format.md, "Open and non-manifold
/// meshes").
std::vector<Eigen::Vector3d> fill_mesh(const Node& fluid, double d, ShapeCache& cache) {
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  if (auto s = fluid.find("scale")) {
    scale = s->json().is_array() ? s->vec3(Sign::Positive)
                                 : Eigen::Vector3d::Constant(s->number(Sign::Positive));
  }
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  if (auto p = fluid.find("position")) position = p->vec3();
  TriangleMesh mesh = *load_mesh_once(fluid.at("file"), cache);
  for (Eigen::Vector3d& v : mesh.vertices) v = v.cwiseProduct(scale);
  // The box around the mesh bounds the count before anything is filled.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  if (!mesh.vertices.empty()) {
    const Eigen::Vector3d cells = ((hi - lo) / d).array() + 1.0;
    check_count(fluid, cells.x() * cells.y() * cells.z(), cache);
  }
  VoxelizeOptions options;
  options.diameter = fluid_rest_spacing(d);
  Result<ParticleSet> filled = voxelize(mesh, options);
  if (!filled) fluid.at("file").fail(filled.message());
  std::vector<Eigen::Vector3d> points;
  points.reserve(filled.value().points.size());
  for (const Eigen::Vector3f& p : filled.value().points)
    points.push_back(p.cast<double>() + position);
  return points;
}

/// An emitter (docs/scene-format.md, "Emitters"): its nozzle, its schedule and its parked
/// particles.
FluidEmitter read_emitter(const Node& fluid, double d, const ShapeCache& cache) {
  FluidEmitter e;
  e.position = fluid.at("position").vec3();
  const Node direction = fluid.at("direction");
  const Eigen::Vector3d n = direction.vec3();
  const double largest = n.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) direction.fail("must not be zero (the way the stream leaves the nozzle)");
  e.direction = (n / largest).normalized();  // scaled first: no overflow of the norm near 3e38
  e.speed = fluid.at("speed").number(Sign::Positive);
  const Node rate = fluid.at("rate");
  e.rate = rate.number(Sign::Positive);
  if (e.rate * d / e.speed > static_cast<double>(kEmitterNozzleLimit)) {
    rate.fail(fmt::format(
        "{} particles a second at {} m/s is a nozzle of {:.4g} particles, more than {} (lower the "
        "rate or raise the speed)",
        e.rate, e.speed, e.rate * d / e.speed, kEmitterNozzleLimit));
  }
  const Node limit = fluid.at("max_particles");
  e.max_particles = static_cast<std::uint64_t>(limit.integer(1, std::int64_t{1} << 40));
  if (static_cast<std::int64_t>(e.max_particles) > cache.max_particles) {
    limit.fail(fmt::format("{} particles, more than settings.max_particles ({})", e.max_particles,
                           cache.max_particles));
  }
  if (auto t = fluid.find("start")) e.start = t->number(Sign::NonNegative);
  if (auto t = fluid.find("stop")) {
    e.stop = t->number(Sign::Positive);
    if (!(e.stop > e.start)) {
      t->fail(fmt::format("must be later than start ({} s <= {} s)", e.stop, e.start));
    }
  }
  e.nozzle = emitter_nozzle(e.direction, e.rate, e.speed, d);
  e.layer_period = static_cast<double>(e.nozzle.size()) / e.rate;
  return e;
}

}  // namespace

bool is_fluid(const Node& entry) {
  const Json& json = entry.json();
  if (!json.is_object()) return false;
  const auto kind = json.find("kind");
  return kind != json.end() && kind->is_string() && *kind == "fluid";
}

FluidSpec read_fluid(const Node& entry, std::size_t index, ShapeCache& cache, const Scene& scene) {
  entry.expect_object({"name", "kind", "material", "fluid", "velocity", "color"});
  const Node fluid = entry.at("fluid");
  if (scene.settings.contact_model != ContactModel::Positions) {
    entry.at("kind").fail(
        "a fluid needs \"contact_model\": \"position\" in /settings (its density constraint is "
        "solved in the position solver's substeps: docs/fluids.md)");
  }
  FluidSpec spec;
  spec.name = entry.has("name") ? entry.at("name").string() : fmt::format("body{}", index);
  spec.material = entry.has("material") ? find_material(entry.at("material"), scene.materials) : 0;
  if (auto v = entry.find("velocity")) spec.velocity = v->vec3();
  if (auto c = entry.find("color")) spec.color = read_color(*c);

  const std::string type = fluid.has("type") ? fluid.at("type").string() : "";
  if (type == "box") {
    fluid.expect_object({"type", "min", "max", "diameter"});
  } else if (type == "sphere") {
    fluid.expect_object({"type", "center", "radius", "diameter"});
  } else if (type == "mesh") {
    fluid.expect_object({"type", "file", "scale", "position", "diameter"});
  } else if (type == "emitter") {
    fluid.expect_object({"type", "position", "direction", "speed", "rate", "max_particles", "start",
                         "stop", "diameter"});
    if (auto v = entry.find("velocity")) {
      v->fail(
          "an emitter's particles leave at its \"speed\" along its \"direction\" (drop "
          "\"velocity\")");
    }
  } else if (fluid.has("type")) {
    fluid.at("type").fail(
        fmt::format("unknown fluid volume \"{}\" (allowed: box, sphere, mesh, emitter)", type));
  } else {
    fluid.expect_object({"type", "min", "max", "center", "radius", "file", "scale", "position",
                         "direction", "speed", "rate", "max_particles", "start", "stop",
                         "diameter"});
    fluid.fail(
        "missing required key \"type\" (the volume the fluid fills: \"box\", \"sphere\" or "
        "\"mesh\"; or \"emitter\")");
  }
  spec.diameter = cache.default_diameter;
  if (auto d = fluid.find("diameter")) spec.diameter = d->number(Sign::Positive);
  if (type == "emitter") {
    spec.emitter = read_emitter(fluid, spec.diameter, cache);
    spec.points = emitter_parking(*spec.emitter, spec.diameter);
  } else {
    spec.points = type == "box"      ? fill_box(fluid, spec.diameter, cache)
                  : type == "sphere" ? fill_sphere(fluid, spec.diameter, cache)
                                     : fill_mesh(fluid, spec.diameter, cache);
  }
  if (spec.points.empty()) fluid.fail("the volume holds no particle");
  for (const Eigen::Vector3d& p : spec.points) {
    if (!(p.cwiseAbs().maxCoeff() <= static_cast<double>(std::numeric_limits<float>::max()))) {
      fluid.fail("the volume lies outside the float range");
    }
  }
  return spec;
}

}  // namespace motes::scene_detail

namespace motes {

std::vector<Eigen::Vector3d> emitter_nozzle(const Eigen::Vector3d& direction, double rate,
                                            double speed, double d) {
  const Eigen::Vector3d n = direction.normalized();
  const Eigen::Vector3d a =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = (a - a.dot(n) * n).normalized();
  const Eigen::Vector3d w = n.cross(u);
  // Particles a layer for a layer per d of travel, at most kEmitterNozzleLimit (read_emitter
  // refuses more).
  const double want = std::min(rate * d / speed, static_cast<double>(kEmitterNozzleLimit));
  // Discs of squared radius q (in spacings): grow q while the count gets closer to `want`; the
  // count grows by the lattice points on each circle i^2 + j^2 = q.
  const auto on_circle = [](std::int64_t q) {
    std::int64_t c = 0;
    for (std::int64_t i = 0; i * i <= q; ++i) {
      const auto j =
          static_cast<std::int64_t>(std::llround(std::sqrt(static_cast<double>(q - i * i))));
      if (j * j != q - i * i) continue;
      c += (i == 0 ? 1 : 2) * (j == 0 ? 1 : 2);
    }
    return c;
  };
  std::int64_t best = 0, count = 1, best_count = 1;
  for (std::int64_t q = 1; static_cast<double>(count) < want; ++q) {
    count += on_circle(q);
    if (std::abs(static_cast<double>(count) - want) <
        std::abs(static_cast<double>(best_count) - want)) {
      best = q;
      best_count = count;
    }
  }
  std::vector<Eigen::Vector3d> points;
  const auto r = static_cast<std::int64_t>(std::sqrt(static_cast<double>(best)));
  for (std::int64_t j = -r - 1; j <= r + 1; ++j) {
    for (std::int64_t i = -r - 1; i <= r + 1; ++i) {
      if (i * i + j * j <= best) {
        points.push_back(d * (static_cast<double>(i) * u + static_cast<double>(j) * w));
      }
    }
  }
  return points;
}

std::vector<Eigen::Vector3d> emitter_parking(const FluidEmitter& e, double d) {
  const auto side =
      static_cast<std::uint64_t>(std::ceil(std::cbrt(static_cast<double>(e.max_particles))));
  const double step = kEmitterParkSpacing * d;
  const Eigen::Vector3d origin = e.position - Eigen::Vector3d(0.0, kEmitterParkDepth, 0.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(e.max_particles);
  for (std::uint64_t k = 0; k < e.max_particles; ++k) {
    const std::uint64_t x = k % side, y = (k / side) % side, z = k / (side * side);
    points.push_back(origin + step * Eigen::Vector3d(static_cast<double>(x),
                                                     -static_cast<double>(y),
                                                     static_cast<double>(z)));
  }
  return points;
}

}  // namespace motes
