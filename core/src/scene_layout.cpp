// The scene's layout on the device, before anything is written (scene_layout.h): counting and
// checking, the sizes, the tables, the halo, the step's parameters and the setup's fingerprint;
// the bodies' builders are in scene_layout_bodies.cpp, the cloths' and ropes' in
// scene_layout_linked.cpp.
#include "scene_layout.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "contact_laws.h"
#include "motes/checkpoint.h"
#include "motes/fluid.h"
#include "shared/halo.h"

namespace motes {

SceneBodies scene_bodies(const Scene& scene) {
  SceneBodies out;
  out.bodies.reserve(scene.bodies.size() + scene.linked.size() + scene.fluids.size());
  for (const BodySpec& b : scene.bodies) {
    BodyInfo info;
    info.name = b.name;
    info.kind = b.kind;
    info.first_particle = static_cast<std::uint32_t>(out.particles);
    info.particle_count = static_cast<std::uint32_t>(b.shape ? b.shape->points.size() : 0);
    info.soft = b.soft.has_value();
    out.particles += b.shape ? b.shape->points.size() : 0;
    if (b.shape) out.largest_diameter = std::max(out.largest_diameter, b.shape->diameter);
    out.bodies.push_back(std::move(info));
  }
  for (const LinkedSpec& l : scene.linked) {
    BodyInfo info;
    info.name = l.name;
    info.linked = true;
    info.first_particle = static_cast<std::uint32_t>(out.particles);
    info.particle_count = static_cast<std::uint32_t>(l.points.size());
    out.particles += l.points.size();
    out.largest_diameter = std::max(out.largest_diameter, l.diameter);
    out.bodies.push_back(std::move(info));
  }
  for (const FluidSpec& f : scene.fluids) {
    BodyInfo info;
    info.name = f.name;
    info.fluid = true;
    info.first_particle = static_cast<std::uint32_t>(out.particles);
    info.particle_count = static_cast<std::uint32_t>(f.points.size());
    out.particles += f.points.size();
    out.largest_diameter = std::max(out.largest_diameter, f.diameter);
    out.bodies.push_back(std::move(info));
  }
  return out;
}

namespace layout {
namespace {

/// Bytes of Sizes before its fields of runs over MPI ranks: the whole struct until they came
/// (14 words), hashed as the setup's fingerprint (Simulation::setup_hash).
constexpr std::size_t kSizesBeforeMpi = offsetof(Sizes, halo_index);
static_assert(kSizesBeforeMpi == 14 * sizeof(std::uint32_t),
              "the setup hash covers the Sizes of single-process checkpoints");

/// The settings every scene needs.
Status check_settings(const Scene& scene) {
  const Settings& settings = scene.settings;
  if (!(settings.dt > 0.0) || !std::isfinite(settings.dt) || settings.substeps < 1) {
    return Status::error(fmt::format("{}: dt must be > 0 and substeps >= 1 (dt {}, substeps {})",
                                     scene.source, settings.dt, settings.substeps));
  }
  if (scene.materials.empty()) return Status::error(scene.source + ": the scene has no material");
  if (settings.neighbour_capacity < 1) {
    return Status::error(fmt::format("{}: neighbour_capacity must be at least 1 (got {})",
                                     scene.source, settings.neighbour_capacity));
  }
  const bool impulses = settings.contact_model == ContactModel::Impulses;
  if (impulses && settings.impulse_iterations < 1) {
    return Status::error(fmt::format("{}: impulse_iterations must be at least 1 (got {})",
                                     scene.source, settings.impulse_iterations));
  }
  if (impulses && (settings.impulse_substeps < 1 || settings.impulse_substeps > 64)) {
    return Status::error(fmt::format("{}: impulse_substeps must be 1 to 64 (got {})", scene.source,
                                     settings.impulse_substeps));
  }
  return Status::ok();
}

/// The scene's bodies: each has particles, a soft one is dynamic; the particles of each kind.
Status count_bodies(const Scene& scene, SceneCounts& c) {
  for (const BodySpec& b : scene.bodies) {
    if (!b.shape || b.shape->points.empty()) {
      return Status::error(fmt::format("{}: body '{}' has no particles", scene.source, b.name));
    }
    c.body_particles += b.shape->points.size();
    if (b.soft) {
      if (b.kind != BodyKind::Dynamic) {
        return Status::error(
            fmt::format("{}: body '{}' is static and soft: a static body is "
                        "rigid (remove \"soft\" or make it dynamic)",
                        scene.source, b.name));
      }
      c.soft_particles += b.shape->points.size();
    } else if (!is_free_sphere(b, c.impulses)) {
      c.rigid_particles += b.shape->points.size();
      ++c.rigid_bodies;
    }
  }
  return Status::ok();
}

/// The scene's cloths and ropes: how many, their particles, their constraints.
Status count_linked(const Scene& scene, SceneCounts& c) {
  if (scene.linked.size() > kLinkedMaxObjects) {
    return Status::error(fmt::format("{}: {} cloths and ropes; motes supports at most {}",
                                     scene.source, scene.linked.size(), kLinkedMaxObjects));
  }
  for (const LinkedSpec& l : scene.linked) {
    const bool mesh = l.lattice.empty() && l.kind == LinkedKind::Cloth;
    if (l.points.empty() || (!mesh && l.lattice.size() != l.points.size()) ||
        (mesh && l.points.size() > kLinkedMaxMeshPoints)) {
      return Status::error(fmt::format(
          "{}: '{}' has no particles, not one lattice place each, or (a cloth from a mesh) more "
          "than {} particles",
          scene.source, l.name, kLinkedMaxMeshPoints));
    }
    c.constraints += l.links.size() + l.attached.size();
  }
  return Status::ok();
}

}  // namespace

bool is_free_sphere(const BodySpec& body, bool impulses) {
  return !impulses && body.kind == BodyKind::Dynamic && !body.soft &&
         body.shape->points.size() == 1 && body.angular_velocity.isZero(0.0);
}

Result<SceneCounts> count_scene(const Scene& scene, const SceneBodies& bodies,
                                const HaloLists* halo) {
  if (Status st = check_settings(scene); !st) return st;
  SceneCounts c;
  c.impulses = rigid_contacts_without_forces(scene.settings.contact_model);
  if (Status st = count_bodies(scene, c); !st) return st;
  if (Status st = count_linked(scene, c); !st) return st;
  for (const FluidSpec& f : scene.fluids) {
    if (f.points.empty()) {
      return Status::error(fmt::format("{}: fluid '{}' has no particles", scene.source, f.name));
    }
    if (f.material < 0 || static_cast<std::size_t>(f.material) >= scene.materials.size()) {
      return Status::error(
          fmt::format("{}: fluid '{}' has no valid material", scene.source, f.name));
    }
    c.fluid_particles += f.points.size();
  }
  c.body_particles += c.fluid_particles;
  c.particles = bodies.particles;
  if (c.particles > std::numeric_limits<std::uint32_t>::max() / 2) {
    return Status::error(fmt::format("{}: {} particles is more than motes supports (2^31)",
                                     scene.source, c.particles));
  }
  if (c.constraints > std::numeric_limits<std::uint32_t>::max() / 2) {
    return Status::error(fmt::format("{}: {} constraints is more than motes supports (2^31)",
                                     scene.source, c.constraints));
  }
  const Settings& settings = scene.settings;
  if (settings.constraint_iterations < 1 || !(settings.link_damping >= 0.0)) {
    return Status::error(fmt::format(
        "{}: constraint_iterations must be at least 1 and link_damping >= 0 (got {} and {})",
        scene.source, settings.constraint_iterations, settings.link_damping));
  }
  // One rank of a run over MPI ranks builds the grid the whole scene would have (its largest
  // diameter, hence cell and skin, and its table size: count_sizes), so that cells hash alike on
  // every rank and a particle meets its partners in the same order at any rank count.
  c.max_diameter = bodies.largest_diameter;
  if (halo != nullptr) c.max_diameter = std::max(c.max_diameter, halo->scene_diameter);
  for (const FluidSpec& f : scene.fluids) {
    c.max_fluid_support = std::max(c.max_fluid_support, kFluidSupportDiameters * f.diameter);
  }
  return c;
}

Sizes count_sizes(const Scene& scene, const SceneCounts& counts, const HaloLists* halo) {
  Sizes s;
  s.particles = static_cast<std::uint32_t>(counts.particles);
  s.rigid_particles = static_cast<std::uint32_t>(counts.rigid_particles);
  s.bodies = static_cast<std::uint32_t>(counts.rigid_bodies);
  s.table = grid_table_size(
      halo != nullptr ? std::max<std::uint32_t>(halo->scene_particles, s.particles) : s.particles);
  s.materials = static_cast<std::uint32_t>(scene.materials.size());
  s.planes = static_cast<std::uint32_t>(scene.planes.size());
  s.neighbour_capacity = static_cast<std::uint32_t>(scene.settings.neighbour_capacity);
  s.constraints = static_cast<std::uint32_t>(
      std::min<std::uint64_t>(counts.constraints, std::numeric_limits<std::uint32_t>::max()));
  s.soft_particles = static_cast<std::uint32_t>(counts.soft_particles);
  s.impulse = counts.impulses ? 1u : 0u;
  s.fluid_particles = static_cast<std::uint32_t>(counts.fluid_particles);
  return s;
}

TableLayout build_tables(const Scene& scene) {
  TableLayout t;
  for (const PlaneSpec& pl : scene.planes) {
    const Eigen::Vector3d nrm = pl.normal.normalized();
    shared::PlaneData pd{};
    pd.normal_offset = to_vec4(nrm, nrm.dot(pl.point));
    pd.material = static_cast<std::uint32_t>(pl.material);
    t.planes.push_back(pd);
  }
  t.laws = contact_law_table(scene.materials);
  return t;
}

Status build_halo(const std::string& source, const HaloLists& halo, HostLayout& out) {
  // Each listed body's particles as device indices, and a rigid body's index.
  std::array<std::vector<std::uint32_t>, 4> parts;
  const auto add_entries = [&](const std::vector<std::uint32_t>& list,
                               std::vector<std::uint32_t>& particles,
                               std::vector<std::uint32_t>& rigid) -> Status {
    for (const std::uint32_t b : list) {
      if (b >= out.bodies.size()) {
        return Status::error(
            fmt::format("{}: halo list names body {} of {}", source, b, out.bodies.size()));
      }
      const BodyInfo& info = out.bodies[b];
      const bool body_state = info.has_body_state();
      const std::uint32_t index = out.device_index[b];
      const std::uint32_t first = body_state ? out.rigid.first[index] : index;
      for (std::uint32_t k = 0; k < info.particle_count; ++k) particles.push_back(first + k);
      if (body_state) rigid.push_back(index);
    }
    return Status::ok();
  };
  if (Status st = add_entries(halo.send, parts[0], parts[1]); !st) return st;
  if (Status st = add_entries(halo.receive, parts[2], parts[3]); !st) return st;
  std::uint64_t data = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    out.halo.entries[k] = static_cast<std::uint32_t>(parts[k].size());
    out.halo.index.insert(out.halo.index.end(), parts[k].begin(), parts[k].end());
    if (k % 2 == 1) {
      data = std::max<std::uint64_t>(
          data, std::uint64_t{MOTES_HALO_PARTICLE_VEC4S} * parts[k - 1].size() +
                    std::uint64_t{MOTES_HALO_BODY_VEC4S} * parts[k].size());
    }
  }
  if (data > std::numeric_limits<std::uint32_t>::max() / 2) {
    return Status::error(fmt::format("{}: a halo of {} vec4s", source, data));
  }
  out.sizes.halo_index = static_cast<std::uint32_t>(out.halo.index.size());
  out.sizes.halo_data = static_cast<std::uint32_t>(data);
  out.sizes.partition = 1;
  return Status::ok();
}

shared::StepParams build_params(const Settings& settings, const SceneCounts& counts,
                                const HostLayout& layout) {
  const Sizes& sizes = layout.sizes;
  const double skin = Simulation::neighbour_skin(settings, counts.max_diameter);
  shared::StepParams p{};
  p.gravity_dt = to_vec4(settings.gravity, settings.dt / settings.substeps);
  p.particle_count = sizes.particles;
  p.body_count = sizes.bodies;
  p.table_mask = sizes.table - 1;
  p.plane_count = sizes.planes;
  // Cells hold every pair a list can hold: cell edge = max(largest diameter, largest fluid
  // support h) + skin (without fluid, largest diameter + skin as before).
  const double reach = std::max(counts.max_diameter, counts.max_fluid_support);
  p.cell_size = static_cast<float>(reach + skin);
  p.inv_cell_size = static_cast<float>(1.0 / (reach + skin));
  p.material_count = sizes.materials;
  p.flags = (settings.clamp_attraction ? MOTES_FLAG_CLAMP_ATTRACTION : 0u) |
            (counts.impulses ? MOTES_FLAG_IMPULSE : 0u);
  p.rigid_particle_count = sizes.rigid_particles;
  p.neighbour_capacity = sizes.neighbour_capacity;
  p.neighbour_skin = static_cast<float>(skin);
  p.linked_first = static_cast<std::uint32_t>(counts.body_particles);
  p.soft_first = static_cast<std::uint32_t>(counts.body_particles - counts.soft_particles);
  p.cluster_count = static_cast<std::uint32_t>(layout.soft.clusters.clusters.size());
  p.fluid_count = static_cast<std::uint32_t>(counts.fluid_particles);
  p.fluid_first = counts.fluid_particles == 0 ? 0u : p.soft_first - p.fluid_count;
  p.linked_damping =
      static_cast<float>(-std::expm1(-settings.link_damping * settings.dt / settings.substeps));
  return p;
}

Fingerprint fingerprint(const Settings& settings, const HostLayout& layout) {
  // Every fixed input of a step (checkpoints load only where it is equal). Sizes before the
  // fields of runs over MPI ranks: a single process's hash (and so a checkpoint's) is what it
  // was before they existed, and the halo's sizes, which change with every partition of a run
  // over MPI ranks, say nothing about the physics.
  std::uint64_t h = fnv1a64(&layout.sizes, kSizesBeforeMpi);
  // StepParams up to the fluid's fields, which join the hash only in a scene with fluid (a scene
  // without keeps the fingerprint it had before they existed).
  h = fnv1a64(&layout.params, offsetof(shared::StepParams, fluid_first), h);
  if (layout.params.fluid_count != 0) {
    h = fnv1a64(&layout.params.fluid_first,
                sizeof layout.params - offsetof(shared::StepParams, fluid_first), h);
  }
  const std::int64_t counts[2] = {settings.substeps, settings.constraint_iterations};
  h = fnv1a64(counts, sizeof counts, h);
  h = fnv1a64(&settings.dt, sizeof settings.dt, h);
  if (settings.contact_model == ContactModel::Impulses) {
    // The impulse stage's sweeps and substeps (not hashed before they existed).
    const std::int64_t stage[2] = {settings.impulse_iterations, settings.impulse_substeps};
    h = fnv1a64(stage, sizeof stage, h);
  } else if (settings.contact_model == ContactModel::Positions) {
    const std::int64_t model = 2;
    h = fnv1a64(&model, sizeof model, h);
  }
  const auto add = [&h](const auto& v) { h = fnv1a64(v.data(), v.size() * sizeof(v[0]), h); };
  add(layout.rigid.local);
  add(layout.particles.body);
  add(layout.particles.material);
  add(layout.rigid.inv_inertia);
  add(layout.rigid.first);
  add(layout.tables.laws);
  add(layout.tables.planes);
  add(layout.linked.colouring.constraints);
  add(layout.linked.colouring.first);
  add(layout.soft.clusters.clusters);
  add(layout.soft.clusters.members);
  add(layout.soft.gather);
  add(layout.linked.exclusions);
  if (!layout.fluid_materials.empty()) {
    // The fluids' materials and sweeps (not hashed in a scene without fluid).
    add(layout.fluid_materials);
    const std::int64_t sweeps = settings.fluid_iterations;
    h = fnv1a64(&sweeps, sizeof sweeps, h);
  }
  for (const auto& [body, q] : layout.sphere_turns) {
    h = fnv1a64(&body, sizeof body, h);
    h = fnv1a64(&q, sizeof q, h);
  }
  for (const EmitterRange& e : layout.emitters) {  // their schedules (only in a scene with one)
    const FluidEmitter& f = e.emitter;
    const double words[11] = {f.position.x(),  f.position.y(),  f.position.z(), f.direction.x(),
                              f.direction.y(), f.direction.z(), f.speed,        f.rate,
                              f.start,         f.stop,          f.layer_period};
    h = fnv1a64(words, sizeof words, h);
    const std::uint64_t range[3] = {e.first, e.count, f.nozzle.size()};
    h = fnv1a64(range, sizeof range, h);
  }
  const ParticleLayout& p = layout.particles;
  const std::uint64_t w = particle_w_hash(p.pos, p.vel, layout.emitters);
  return {fnv1a64(&w, sizeof w, h), w};
}

}  // namespace layout
}  // namespace motes
