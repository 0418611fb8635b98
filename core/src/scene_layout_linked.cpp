// The scene's cloths and ropes laid out for the device (scene_layout.h): their particles after
// the bodies', their links and attachments as constraints, and the pairs within two links of a
// cloth made from a mesh.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "scene_layout.h"
#include "shared/links.h"

namespace motes::layout {
namespace {

using shared::vec4;

/// LinkExclusions (shared/links.h), when a cloth is made from a mesh: a start for every linked
/// particle, then the lists.
struct Exclusions {
  std::vector<std::uint32_t> start, list;
};

/// The constraint that holds cloth or rope particle `point` to a body whose particles are
/// [first, first + count): from the body's particle nearest the point (the first of equals), at
/// their distance.
shared::Constraint attachment_constraint(const std::vector<vec4>& pos, std::uint32_t first,
                                         std::uint32_t count, std::uint32_t point) {
  const auto distance = [&](std::uint32_t i) {
    const Eigen::Vector3d d(static_cast<double>(pos[i].x) - static_cast<double>(pos[point].x),
                            static_cast<double>(pos[i].y) - static_cast<double>(pos[point].y),
                            static_cast<double>(pos[i].z) - static_cast<double>(pos[point].z));
    return d.norm();
  };
  std::uint32_t nearest = first;
  for (std::uint32_t k = 1; k < count; ++k) {
    if (distance(first + k) < distance(nearest)) nearest = first + k;
  }
  shared::Constraint c{};
  c.a = nearest;
  c.b = point;
  c.rest = static_cast<float>(distance(nearest));
  c.stiffness = 1.0f;
  return c;
}

/// Cloth or rope `li`'s particles [first, first + count), its mass and its first particle.
Status build_linked_particles(const Scene& scene, std::size_t li, std::uint32_t first,
                              HostLayout& out) {
  const LinkedSpec& spec = scene.linked[li];
  if (spec.material < 0 || static_cast<std::size_t>(spec.material) >= scene.materials.size()) {
    return Status::error(fmt::format("{}: '{}' has no valid material", scene.source, spec.name));
  }
  const Material& mat = scene.materials[static_cast<std::size_t>(spec.material)];
  const double particle_mass = linked_particle_mass(mat.density, spec.diameter);
  if (!(particle_mass > 0.0) || !std::isfinite(particle_mass)) {
    return Status::error(fmt::format("{}: '{}' has no mass (density {}, diameter {})", scene.source,
                                     spec.name, mat.density, spec.diameter));
  }
  const auto count = static_cast<std::uint32_t>(spec.points.size());
  std::vector<bool> pinned(count, false);
  for (const std::uint32_t k : spec.pinned) {
    if (k >= count) {
      return Status::error(
          fmt::format("{}: '{}' pins particle {} of {}", scene.source, spec.name, k, count));
    }
    pinned[k] = true;
  }
  out.bodies[scene.bodies.size() + li].mass = particle_mass * static_cast<double>(count);
  out.device_index.push_back(first);
  const bool mesh = spec.lattice.empty();
  ParticleLayout& p = out.particles;
  for (std::uint32_t k = 0; k < count; ++k) {
    const std::uint32_t i = first + k;
    p.pos[i] = to_vec4(spec.points[k], 0.5 * spec.diameter);
    p.vel[i] = pinned[k] ? vec4(0.0f) : to_vec4(spec.velocity, 1.0 / particle_mass);
    p.material[i] = static_cast<std::uint32_t>(spec.material);
    if (mesh) {
      p.body[i] = shared::linked_mesh_body(static_cast<std::uint32_t>(li), k);
      continue;
    }
    const std::array<std::uint32_t, 2> uv = spec.lattice[k];
    if (uv[0] >= kLinkedMaxSide || uv[1] >= kLinkedMaxSide) {
      return Status::error(fmt::format("{}: '{}': lattice place ({}, {}) beyond {}", scene.source,
                                       spec.name, uv[0], uv[1], kLinkedMaxSide));
    }
    p.body[i] = shared::linked_body(static_cast<std::uint32_t>(li), uv[0], uv[1]);
  }
  return Status::ok();
}

/// The lists of a cloth or rope's particles (a cloth made from a mesh: the particles within two
/// links; otherwise none), when some cloth of the scene is made from a mesh.
Status add_exclusions(const Scene& scene, const LinkedSpec& spec, std::uint32_t first,
                      Exclusions& out) {
  const auto count = static_cast<std::uint32_t>(spec.points.size());
  const bool mesh = spec.lattice.empty();
  const LinkNeighbourhoods near =
      mesh ? link_neighbourhoods(spec.links, count) : LinkNeighbourhoods{};
  for (std::uint32_t k = 0; k < count; ++k) {
    if (mesh) {
      for (std::uint32_t e = near.start[k]; e < near.start[k + 1]; ++e) {
        out.list.push_back(first + near.list[e]);
      }
    }
    if (out.list.size() > std::numeric_limits<std::uint32_t>::max() / 2) {
      return Status::error(
          fmt::format("{}: the cloths made from meshes have more than 2^31 pairs within two links",
                      scene.source));
    }
    out.start.push_back(static_cast<std::uint32_t>(out.list.size()));
  }
  return Status::ok();
}

/// A cloth's or rope's links, then its attachments to bodies (build_bodies first), as
/// constraints; sizes absorb when a dynamic rigid body takes an attachment's pull.
Status add_constraints(const Scene& scene, const LinkedSpec& spec, std::uint32_t first,
                       HostLayout& out, std::vector<shared::Constraint>& constraints) {
  const auto count = static_cast<std::uint32_t>(spec.points.size());
  for (const LinkSpec& link : spec.links) {
    if (link.a >= count || link.b >= count || link.a == link.b) {
      return Status::error(fmt::format("{}: '{}': a link joins particles {} and {} of {}",
                                       scene.source, spec.name, link.a, link.b, count));
    }
    shared::Constraint c{};
    c.a = first + link.a;
    c.b = first + link.b;
    c.rest = static_cast<float>((spec.points[link.a] - spec.points[link.b]).norm());
    c.stiffness = static_cast<float>(link.stiffness);
    constraints.push_back(c);
  }
  for (const LinkAttachment& a : spec.attached) {
    const auto it = std::find_if(scene.bodies.begin(), scene.bodies.end(),
                                 [&](const BodySpec& b) { return b.name == a.body; });
    if (it == scene.bodies.end() || it->soft || a.point >= count) {
      return Status::error(
          fmt::format("{}: '{}' attaches point {} to '{}': no such point, or "
                      "not a rigid or static body",
                      scene.source, spec.name, a.point, a.body));
    }
    const auto b = static_cast<std::size_t>(it - scene.bodies.begin());
    const BodyInfo& held = out.bodies[b];
    const std::uint32_t index = out.device_index[b];
    const std::uint32_t held_first = held.free_sphere ? index : out.rigid.first[index];
    const shared::Constraint c =
        attachment_constraint(out.particles.pos, held_first, held.particle_count, first + a.point);
    // A dynamic rigid body (not a lean free sphere) takes the constraints' pull as impulses.
    if (!held.free_sphere && out.particles.vel[c.a].w != 0.0f) out.sizes.absorb = 1;
    constraints.push_back(c);
  }
  return Status::ok();
}

}  // namespace

Status build_linked(const Scene& scene, const SceneCounts& counts, HostLayout& out) {
  // Particles [Nl, N), each object's in its own order.
  auto next = static_cast<std::uint32_t>(counts.body_particles);
  std::vector<shared::Constraint> constraints;
  constraints.reserve(out.sizes.constraints);
  const bool any_mesh = std::any_of(scene.linked.begin(), scene.linked.end(),
                                    [](const LinkedSpec& l) { return l.lattice.empty(); });
  Exclusions exclusions;
  if (any_mesh) exclusions.start.push_back(0);
  for (std::size_t li = 0; li < scene.linked.size(); ++li) {
    const LinkedSpec& spec = scene.linked[li];
    if (Status st = build_linked_particles(scene, li, next, out); !st) return st;
    if (any_mesh) {
      if (Status st = add_exclusions(scene, spec, next, exclusions); !st) return st;
    }
    if (Status st = add_constraints(scene, spec, next, out, constraints); !st) return st;
    next += static_cast<std::uint32_t>(spec.points.size());
  }
  out.linked.colouring = colour_constraints(constraints, out.sizes.particles);
  out.sizes.constraint_colours = static_cast<std::uint32_t>(out.linked.colouring.colours());
  std::vector<std::uint32_t>& words = out.linked.exclusions;
  words = std::move(exclusions.start);
  words.insert(words.end(), exclusions.list.begin(), exclusions.list.end());
  if (words.size() > std::numeric_limits<std::uint32_t>::max()) {
    return Status::error(fmt::format("{}: the cloths made from meshes need {} words of lists",
                                     scene.source, words.size()));
  }
  out.sizes.link_exclusions = static_cast<std::uint32_t>(words.size());
  return Status::ok();
}

}  // namespace motes::layout
