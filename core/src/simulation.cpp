// motes::Simulation: turns a Scene into device buffers and runs the step pipeline.
#include "motes/simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <numbers>

#include "contact_laws.h"
#include "motes/checkpoint.h"
#include "motes/cloth.h"
#include "motes/soft.h"
#include "shared/body_math.h"
#include "shared/energy.h"
#include "shared/halo.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes {

using shared::vec4;

namespace {

/// Bytes of Sizes before its fields of runs over MPI ranks: the whole struct until they came
/// (14 words), hashed as the setup's fingerprint (Simulation::setup_hash).
constexpr std::size_t kSizesBeforeMpi = offsetof(Sizes, halo_index);
static_assert(kSizesBeforeMpi == 14 * sizeof(std::uint32_t),
              "the setup hash covers the Sizes of single-process checkpoints");

vec4 to_vec4(const Eigen::Vector3d& v, double w) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()),
          static_cast<float>(w)};
}

vec4 to_quat(const Eigen::Quaterniond& q) {
  return {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()),
          static_cast<float>(q.w())};
}

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

template <typename T>
Status write_vector(Device& d, Buffer b, const std::vector<T>& v) {
  return d.write(b, v.data(), v.size() * sizeof(T));
}

template <typename T>
Status read_vector(Device& d, Buffer b, std::vector<T>& v, std::size_t count) {
  v.resize(count);
  return d.read(b, v.data(), count * sizeof(T));
}

}  // namespace

Result<std::unique_ptr<Simulation>> Simulation::create(const Scene& scene,
                                                       std::unique_ptr<Device> device) {
  if (!device) return Status::error("Simulation::create: no device");
  std::unique_ptr<Simulation> sim(new Simulation());
  sim->device_ = std::move(device);
  if (Status s = sim->upload(scene, nullptr); !s) return s;
  return sim;
}

Result<std::unique_ptr<Simulation>> Simulation::create(const Scene& scene,
                                                       std::unique_ptr<Device> device,
                                                       const HaloLists& halo) {
  if (!device) return Status::error("Simulation::create: no device");
  std::unique_ptr<Simulation> sim(new Simulation());
  sim->device_ = std::move(device);
  if (Status s = sim->upload(scene, &halo); !s) return s;
  return sim;
}

std::unique_ptr<Device> Simulation::take_device(std::unique_ptr<Simulation> sim) {
  if (!sim) return nullptr;
  (void)sim->device_->synchronize();
  sim->halo_out_.reset();  // freed through the device, before it goes
  sim->halo_in_.reset();
  return std::move(sim->device_);
}

Status Simulation::upload(const Scene& scene, const HaloLists* halo) {
  settings_ = scene.settings;
  if (!(settings_.dt > 0.0) || !std::isfinite(settings_.dt) || settings_.substeps < 1) {
    return Status::error(fmt::format("{}: dt must be > 0 and substeps >= 1 (dt {}, substeps {})",
                                     scene.source, settings_.dt, settings_.substeps));
  }
  if (scene.materials.empty()) return Status::error(scene.source + ": the scene has no material");
  if (settings_.neighbour_capacity < 1) {
    return Status::error(fmt::format("{}: neighbour_capacity must be at least 1 (got {})",
                                     scene.source, settings_.neighbour_capacity));
  }

  // Count first, so an impossible size is refused before anything is allocated. Free spheres
  // (dynamic one-particle bodies without spin) go after every rigid body's particles.
  std::uint64_t n = 0;
  std::uint64_t rigid_particles = 0;
  std::uint64_t rigid_bodies = 0;
  std::uint64_t soft_particles = 0;
  double max_diameter = 0.0;
  // With impulse contacts every rigid body, one-particle ones too, is integrated as a body (an
  // impulse at the contact point makes any sphere spin).
  const bool impulses = settings_.contact_model == ContactModel::Impulses;
  if (impulses && settings_.impulse_iterations < 1) {
    return Status::error(fmt::format("{}: impulse_iterations must be at least 1 (got {})",
                                     scene.source, settings_.impulse_iterations));
  }
  if (impulses && (settings_.impulse_substeps < 1 || settings_.impulse_substeps > 64)) {
    return Status::error(fmt::format("{}: impulse_substeps must be 1 to 64 (got {})", scene.source,
                                     settings_.impulse_substeps));
  }
  const auto is_free_sphere = [impulses](const BodySpec& b) {
    return !impulses && b.kind == BodyKind::Dynamic && !b.soft && b.shape->points.size() == 1 &&
           b.angular_velocity.isZero(0.0);
  };
  for (const BodySpec& b : scene.bodies) {
    if (!b.shape || b.shape->points.empty()) {
      return Status::error(fmt::format("{}: body '{}' has no particles", scene.source, b.name));
    }
    n += b.shape->points.size();
    if (b.soft) {
      if (b.kind != BodyKind::Dynamic) {
        return Status::error(
            fmt::format("{}: body '{}' is static and soft: a static body is "
                        "rigid (remove \"soft\" or make it dynamic)",
                        scene.source, b.name));
      }
      soft_particles += b.shape->points.size();
    } else if (!is_free_sphere(b)) {
      rigid_particles += b.shape->points.size();
      ++rigid_bodies;
    }
    max_diameter = std::max(max_diameter, b.shape->diameter);
  }
  const std::uint64_t body_particles = n;
  if (scene.linked.size() > kLinkedMaxObjects) {
    return Status::error(fmt::format("{}: {} cloths and ropes; motes supports at most {}",
                                     scene.source, scene.linked.size(), kLinkedMaxObjects));
  }
  std::uint64_t constraint_count = 0;
  for (const LinkedSpec& l : scene.linked) {
    const bool mesh = l.lattice.empty() && l.kind == LinkedKind::Cloth;
    if (l.points.empty() || (!mesh && l.lattice.size() != l.points.size()) ||
        (mesh && l.points.size() > kLinkedMaxMeshPoints)) {
      return Status::error(fmt::format(
          "{}: '{}' has no particles, not one lattice place each, or (a cloth from a mesh) more "
          "than {} particles",
          scene.source, l.name, kLinkedMaxMeshPoints));
    }
    n += l.points.size();
    constraint_count += l.links.size() + l.attached.size();
    max_diameter = std::max(max_diameter, l.diameter);
  }
  if (n > std::numeric_limits<std::uint32_t>::max() / 2) {
    return Status::error(
        fmt::format("{}: {} particles is more than motes supports (2^31)", scene.source, n));
  }
  // One rank of a run over MPI ranks builds the grid the whole scene would have (its largest
  // diameter, hence cell and skin, and its table size), so that cells hash alike on every rank
  // and a particle meets its partners in the same order at any rank count.
  if (halo != nullptr) max_diameter = std::max(max_diameter, halo->scene_diameter);
  const double skin = neighbour_skin(settings_, max_diameter);
  sizes_.particles = static_cast<std::uint32_t>(n);
  sizes_.rigid_particles = static_cast<std::uint32_t>(rigid_particles);
  sizes_.bodies = static_cast<std::uint32_t>(rigid_bodies);
  sizes_.table = grid_table_size(
      halo != nullptr ? std::max<std::uint32_t>(halo->scene_particles, sizes_.particles)
                      : sizes_.particles);
  sizes_.materials = static_cast<std::uint32_t>(scene.materials.size());
  sizes_.planes = static_cast<std::uint32_t>(scene.planes.size());
  sizes_.neighbour_capacity = static_cast<std::uint32_t>(settings_.neighbour_capacity);
  sizes_.constraints = static_cast<std::uint32_t>(
      std::min<std::uint64_t>(constraint_count, std::numeric_limits<std::uint32_t>::max()));
  if (constraint_count > std::numeric_limits<std::uint32_t>::max() / 2) {
    return Status::error(fmt::format("{}: {} constraints is more than motes supports (2^31)",
                                     scene.source, constraint_count));
  }
  if (settings_.constraint_iterations < 1 || !(settings_.link_damping >= 0.0)) {
    return Status::error(fmt::format(
        "{}: constraint_iterations must be at least 1 and link_damping >= 0 (got {} and {})",
        scene.source, settings_.constraint_iterations, settings_.link_damping));
  }

  sizes_.soft_particles = static_cast<std::uint32_t>(soft_particles);
  sizes_.impulse = impulses ? 1u : 0u;
  Device& d = *device_;
  // Device memory and buffer limits: refuse before allocating anything, with both numbers and the
  // largest particle count that fits (again once the clusters are known, before the device
  // allocates).
  const auto check_memory = [&]() -> Status {
    if (Status st = check_device_fits(d, sizes_); !st) {
      return Status::error(fmt::format("{}: {}", scene.source, st.message()));
    }
    return Status::ok();
  };
  if (Status st = check_memory(); !st) return st;

  std::vector<vec4> ppos, pvel, plocal, bpos, bquat, bvel, bangmom, bangvel, binertia;
  std::vector<std::uint32_t> pbody, pmat;
  try {
    ppos.resize(n);
    pvel.resize(n);
    plocal.reserve(rigid_particles);
    pbody.resize(n);
    pmat.resize(n);
    device_index_.assign(scene.bodies.size(), 0);
  } catch (const std::bad_alloc&) {
    return Status::error(fmt::format("{}: out of host memory for {} particles", scene.source, n));
  }
  rigid_first_.clear();
  sphere_turns_.clear();

  bodies_.clear();
  bodies_.reserve(scene.bodies.size());
  const ParticleSet* last_shape = nullptr;
  int last_material = -1;
  MassProperties mp;
  std::uint32_t scene_particle = 0;
  // Device particles: rigid [0, Nr), free spheres [Nr, Ns), soft [Ns, Nl), linked [Nl, N).
  std::uint32_t next_rigid = 0;
  auto next_free = static_cast<std::uint32_t>(rigid_particles);
  const auto soft_first = static_cast<std::uint32_t>(body_particles - soft_particles);
  std::uint32_t next_soft = soft_first;
  std::uint32_t soft_bodies = 0;
  SoftClusters soft;
  for (std::size_t bi = 0; bi < scene.bodies.size(); ++bi) {
    const BodySpec& spec = scene.bodies[bi];
    if (spec.material < 0 || static_cast<std::size_t>(spec.material) >= scene.materials.size()) {
      return Status::error(
          fmt::format("{}: body '{}' has no valid material", scene.source, spec.name));
    }
    const Material& mat = scene.materials[static_cast<std::size_t>(spec.material)];
    // Repeated bodies share a shape: compute its mass properties once.
    if (spec.shape.get() != last_shape || spec.material != last_material) {
      mp = mass_properties(*spec.shape, mat.density);
      last_shape = spec.shape.get();
      last_material = spec.material;
    }
    if (!(mp.mass > 0.0) || !std::isfinite(mp.mass)) {
      return Status::error(fmt::format("{}: body '{}' has no mass (density {})", scene.source,
                                       spec.name, mat.density));
    }
    const bool dynamic = spec.kind == BodyKind::Dynamic;
    const bool free = is_free_sphere(spec);
    // Body frame = principal axes: orientation = rotation * (principal -> shape frame).
    const Eigen::Quaterniond orient =
        (spec.rotation.normalized() * mp.principal_frame).normalized();
    const Eigen::Matrix3d to_body = mp.principal_frame.toRotationMatrix().transpose();
    const Eigen::Matrix3d rot = orient.toRotationMatrix();
    const Eigen::Vector3d vel = dynamic ? spec.velocity : Eigen::Vector3d::Zero();

    BodyInfo info;
    info.name = spec.name;
    info.kind = spec.kind;
    info.mass = mp.mass;
    info.first_particle = scene_particle;
    info.particle_count = static_cast<std::uint32_t>(spec.shape->points.size());
    info.free_sphere = free;
    info.soft = spec.soft.has_value();
    bodies_.push_back(info);
    scene_particle += info.particle_count;

    const double radius = 0.5 * spec.shape->diameter;
    const double inv_pm = dynamic ? 1.0 / mp.particle_mass : 0.0;
    if (spec.soft) {
      // Free particles of one body (no contact among themselves), pulled to their clusters' goals.
      device_index_[bi] = next_soft;
      std::vector<Eigen::Vector3d> world;
      world.reserve(spec.shape->points.size());
      const std::uint32_t body_word =
          sizes_.bodies + (soft_first - sizes_.rigid_particles) + soft_bodies++;
      for (const Eigen::Vector3f& pt : spec.shape->points) {
        const Eigen::Vector3d offset = rot * (to_body * (pt.cast<double>() - mp.center));
        const std::uint32_t i = next_soft++;
        world.push_back(spec.position + offset);
        ppos[i] = to_vec4(world.back(), radius);
        pvel[i] = to_vec4(vel + spec.angular_velocity.cross(offset), inv_pm);
        pbody[i] = body_word;
        pmat[i] = static_cast<std::uint32_t>(spec.material);
      }
      SoftSpec soft_spec = *spec.soft;
      if (soft_spec.frequency > 0.0) {
        const double turn = 2.0 * std::numbers::pi * soft_spec.frequency * settings_.dt /
                            static_cast<double>(settings_.substeps);
        soft_spec.stiffness = std::min(1.0, turn * turn);
      }
      bodies_.back().first_cluster = static_cast<std::uint32_t>(soft.clusters.size());
      if (Status st = add_soft_body(soft_spec, world, mp.particle_mass,
                                    settings_.dt / static_cast<double>(settings_.substeps),
                                    device_index_[bi], soft);
          !st) {
        return Status::error(
            fmt::format("{}: body '{}': {}", scene.source, spec.name, st.message()));
      }
      bodies_.back().cluster_count =
          static_cast<std::uint32_t>(soft.clusters.size()) - bodies_.back().first_cluster;
      continue;
    }
    if (free) {
      // The particle is the body: its state is the body's; it never turns.
      const std::uint32_t i = next_free++;
      device_index_[bi] = i;
      const vec4 q = to_quat(orient);
      if (q.x != 0.0f || q.y != 0.0f || q.z != 0.0f || q.w != 1.0f) {
        sphere_turns_.emplace_back(static_cast<std::uint32_t>(bi), q);
      }
      const Eigen::Vector3d local = to_body * (spec.shape->points[0].cast<double>() - mp.center);
      ppos[i] = to_vec4(spec.position + rot * local, radius);
      pvel[i] = to_vec4(vel, inv_pm);
      pbody[i] = sizes_.bodies + (i - sizes_.rigid_particles);
      pmat[i] = static_cast<std::uint32_t>(spec.material);
      continue;
    }
    const auto b = static_cast<std::uint32_t>(rigid_first_.size());
    device_index_[bi] = b;
    rigid_first_.push_back(next_rigid);
    const Eigen::Vector3d inv_moments = mp.principal_moments.cwiseInverse();
    const Eigen::Vector3d omega = dynamic ? spec.angular_velocity : Eigen::Vector3d::Zero();
    const Eigen::Vector3d angmom =
        rot * mp.principal_moments.asDiagonal() * rot.transpose() * omega;
    bpos.push_back(to_vec4(spec.position, dynamic ? 1.0 / mp.mass : 0.0));
    bquat.push_back(to_quat(orient));
    bvel.push_back(to_vec4(vel, 0.0));
    bangmom.push_back(to_vec4(angmom, 0.0));
    bangvel.push_back(to_vec4(omega, 0.0));
    binertia.push_back(dynamic ? to_vec4(inv_moments, 0.0) : vec4(0.0f));
    for (const Eigen::Vector3f& pt : spec.shape->points) {
      const Eigen::Vector3d local = to_body * (pt.cast<double>() - mp.center);
      const std::uint32_t i = next_rigid++;
      plocal.push_back(to_vec4(local, 0.0));
      // Positions and velocities are recomputed on the device by particles_update below.
      ppos[i] = to_vec4(spec.position + rot * local, radius);
      pvel[i] = to_vec4(Eigen::Vector3d::Zero(), inv_pm);
      pbody[i] = b;
      pmat[i] = static_cast<std::uint32_t>(spec.material);
    }
  }
  rigid_first_.push_back(next_rigid);

  // Cloth and ropes after the free spheres: particles [Nl, N), each object's in its own order.
  const auto linked_first = static_cast<std::uint32_t>(body_particles);
  std::vector<shared::Constraint> constraints;
  constraints.reserve(sizes_.constraints);
  std::uint32_t next_linked = linked_first;
  // LinkExclusions (shared/links.h), when a cloth is made from a mesh: a start for every linked
  // particle, then the lists.
  const bool any_mesh = std::any_of(scene.linked.begin(), scene.linked.end(),
                                    [](const LinkedSpec& l) { return l.lattice.empty(); });
  std::vector<std::uint32_t> exclusion_start, exclusion_list;
  if (any_mesh) exclusion_start.push_back(0);
  for (std::size_t li = 0; li < scene.linked.size(); ++li) {
    const LinkedSpec& spec = scene.linked[li];
    if (spec.material < 0 || static_cast<std::size_t>(spec.material) >= scene.materials.size()) {
      return Status::error(fmt::format("{}: '{}' has no valid material", scene.source, spec.name));
    }
    const Material& mat = scene.materials[static_cast<std::size_t>(spec.material)];
    const double particle_mass = linked_particle_mass(mat.density, spec.diameter);
    if (!(particle_mass > 0.0) || !std::isfinite(particle_mass)) {
      return Status::error(fmt::format("{}: '{}' has no mass (density {}, diameter {})",
                                       scene.source, spec.name, mat.density, spec.diameter));
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
    BodyInfo info;
    info.name = spec.name;
    info.kind = BodyKind::Dynamic;
    info.mass = particle_mass * static_cast<double>(count);
    info.first_particle = scene_particle;
    info.particle_count = count;
    info.linked = true;
    bodies_.push_back(info);
    device_index_.push_back(next_linked);
    scene_particle += count;
    const bool mesh = spec.lattice.empty();
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint32_t i = next_linked + k;
      ppos[i] = to_vec4(spec.points[k], 0.5 * spec.diameter);
      pvel[i] = pinned[k] ? vec4(0.0f) : to_vec4(spec.velocity, 1.0 / particle_mass);
      pmat[i] = static_cast<std::uint32_t>(spec.material);
      if (mesh) {
        pbody[i] = shared::linked_mesh_body(static_cast<std::uint32_t>(li), k);
        continue;
      }
      const std::array<std::uint32_t, 2> uv = spec.lattice[k];
      if (uv[0] >= kLinkedMaxSide || uv[1] >= kLinkedMaxSide) {
        return Status::error(fmt::format("{}: '{}': lattice place ({}, {}) beyond {}", scene.source,
                                         spec.name, uv[0], uv[1], kLinkedMaxSide));
      }
      pbody[i] = shared::linked_body(static_cast<std::uint32_t>(li), uv[0], uv[1]);
    }
    if (any_mesh) {
      const LinkNeighbourhoods near =
          mesh ? link_neighbourhoods(spec.links, count) : LinkNeighbourhoods{};
      for (std::uint32_t k = 0; k < count; ++k) {
        if (mesh) {
          for (std::uint32_t e = near.start[k]; e < near.start[k + 1]; ++e) {
            exclusion_list.push_back(next_linked + near.list[e]);
          }
        }
        if (exclusion_list.size() > std::numeric_limits<std::uint32_t>::max() / 2) {
          return Status::error(fmt::format(
              "{}: the cloths made from meshes have more than 2^31 pairs within two links",
              scene.source));
        }
        exclusion_start.push_back(static_cast<std::uint32_t>(exclusion_list.size()));
      }
    }
    for (const LinkSpec& link : spec.links) {
      if (link.a >= count || link.b >= count || link.a == link.b) {
        return Status::error(fmt::format("{}: '{}': a link joins particles {} and {} of {}",
                                         scene.source, spec.name, link.a, link.b, count));
      }
      shared::Constraint c{};
      c.a = next_linked + link.a;
      c.b = next_linked + link.b;
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
      const BodyInfo& held = bodies_[b];
      const std::uint32_t first =
          held.free_sphere ? device_index_[b] : rigid_first_[device_index_[b]];
      const shared::Constraint c =
          attachment_constraint(ppos, first, held.particle_count, next_linked + a.point);
      // A dynamic rigid body (not a lean free sphere) takes the constraints' pull as impulses.
      if (!held.free_sphere && pvel[c.a].w != 0.0f) sizes_.absorb = 1;
      constraints.push_back(c);
    }
    next_linked += count;
  }
  ConstraintColouring colouring = colour_constraints(constraints, sizes_.particles);
  colour_first_ = colouring.first;
  const std::vector<std::uint32_t> gather =
      soft.clusters.empty() ? std::vector<std::uint32_t>{} : cluster_gather(soft);
  std::vector<shared::ClusterFrame> frames(soft.clusters.size());
  for (shared::ClusterFrame& f : frames) f.rotation = vec4(0.0f, 0.0f, 0.0f, 1.0f);

  std::vector<shared::PlaneData> planes;
  for (const PlaneSpec& pl : scene.planes) {
    const Eigen::Vector3d nrm = pl.normal.normalized();
    shared::PlaneData pd{};
    pd.normal_offset = to_vec4(nrm, nrm.dot(pl.point));
    pd.material = static_cast<std::uint32_t>(pl.material);
    planes.push_back(pd);
  }
  const std::vector<shared::ContactLaw> laws = contact_law_table(scene.materials);

  params_ = shared::StepParams{};
  params_.gravity_dt = to_vec4(settings_.gravity, settings_.dt / settings_.substeps);
  params_.particle_count = sizes_.particles;
  params_.body_count = sizes_.bodies;
  params_.table_mask = sizes_.table - 1;
  params_.plane_count = sizes_.planes;
  // Cells hold every pair a list can hold: cell edge = largest diameter + skin.
  params_.cell_size = static_cast<float>(max_diameter + skin);
  params_.inv_cell_size = static_cast<float>(1.0 / (max_diameter + skin));
  params_.material_count = sizes_.materials;
  params_.flags = (settings_.clamp_attraction ? MOTES_FLAG_CLAMP_ATTRACTION : 0u) |
                  (impulses ? MOTES_FLAG_IMPULSE : 0u);
  params_.rigid_particle_count = sizes_.rigid_particles;
  params_.neighbour_capacity = sizes_.neighbour_capacity;
  params_.neighbour_skin = static_cast<float>(skin);
  params_.linked_first = linked_first;
  params_.soft_first = soft_first;
  params_.cluster_count = static_cast<std::uint32_t>(soft.clusters.size());
  params_.linked_damping =
      static_cast<float>(-std::expm1(-settings_.link_damping * settings_.dt / settings_.substeps));

  sizes_.clusters = static_cast<std::uint32_t>(soft.clusters.size());
  sizes_.cluster_members = static_cast<std::uint32_t>(soft.members.size());
  std::vector<std::uint32_t> exclusions = std::move(exclusion_start);
  exclusions.insert(exclusions.end(), exclusion_list.begin(), exclusion_list.end());
  if (exclusions.size() > std::numeric_limits<std::uint32_t>::max()) {
    return Status::error(fmt::format("{}: the cloths made from meshes need {} words of lists",
                                     scene.source, exclusions.size()));
  }
  sizes_.link_exclusions = static_cast<std::uint32_t>(exclusions.size());
  // A rank of a run over MPI ranks: the halo lists as device indices (shared/halo.h).
  std::vector<std::uint32_t> halo_index;
  if (halo != nullptr) {
    std::array<std::vector<std::uint32_t>, 4> parts;
    const auto add_entries = [&](const std::vector<std::uint32_t>& list,
                                 std::vector<std::uint32_t>& particles,
                                 std::vector<std::uint32_t>& rigid) -> Status {
      for (const std::uint32_t b : list) {
        if (b >= bodies_.size()) {
          return Status::error(
              fmt::format("{}: halo list names body {} of {}", scene.source, b, bodies_.size()));
        }
        const BodyInfo& info = bodies_[b];
        const bool body_state = !info.free_sphere && !info.linked && !info.soft;
        const std::uint32_t first = body_state ? rigid_first_[device_index_[b]] : device_index_[b];
        for (std::uint32_t k = 0; k < info.particle_count; ++k) particles.push_back(first + k);
        if (body_state) rigid.push_back(device_index_[b]);
      }
      return Status::ok();
    };
    if (Status st = add_entries(halo->send, parts[0], parts[1]); !st) return st;
    if (Status st = add_entries(halo->receive, parts[2], parts[3]); !st) return st;
    std::uint64_t data = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      halo_entries_[k] = static_cast<std::uint32_t>(parts[k].size());
      halo_index.insert(halo_index.end(), parts[k].begin(), parts[k].end());
      if (k % 2 == 1) {
        data = std::max<std::uint64_t>(
            data, std::uint64_t{MOTES_HALO_PARTICLE_VEC4S} * parts[k - 1].size() +
                      std::uint64_t{MOTES_HALO_BODY_VEC4S} * parts[k].size());
      }
    }
    if (data > std::numeric_limits<std::uint32_t>::max() / 2) {
      return Status::error(fmt::format("{}: a halo of {} vec4s", scene.source, data));
    }
    sizes_.halo_index = static_cast<std::uint32_t>(halo_index.size());
    sizes_.halo_data = static_cast<std::uint32_t>(data);
    sizes_.partition = 1;
    // The packed halo's host memory, sent and received.
    halo_out_count_ = std::size_t{MOTES_HALO_PARTICLE_VEC4S} * halo_entries_[0] +
                      std::size_t{MOTES_HALO_BODY_VEC4S} * halo_entries_[1];
    halo_in_count_ = std::size_t{MOTES_HALO_PARTICLE_VEC4S} * halo_entries_[2] +
                     std::size_t{MOTES_HALO_BODY_VEC4S} * halo_entries_[3];
    for (auto [memory, count] :
         {std::pair{&halo_out_, halo_out_count_}, std::pair{&halo_in_, halo_in_count_}}) {
      *memory = HostMemory<vec4>(
          count == 0 ? nullptr : static_cast<vec4*>(d.allocate_host(count * sizeof(vec4))),
          HostFree{&d});
      if (count > 0 && !*memory) {
        return Status::error(fmt::format("{}: no host memory for a halo of {} bytes", scene.source,
                                         count * sizeof(vec4)));
      }
    }
  }
  if (Status st = check_memory(); !st) return st;

  // The setup's fingerprint: every fixed input of a step (checkpoints load only where it is
  // equal). Computed from the host's copies, so it is the same on every backend.
  // Sizes before the fields of runs over MPI ranks: a single process's hash (and so a
  // checkpoint's) is what it was before they existed, and the halo's sizes, which change with
  // every partition of a run over MPI ranks, say nothing about the physics.
  std::uint64_t h = fnv1a64(&sizes_, kSizesBeforeMpi);
  h = fnv1a64(&params_, sizeof params_, h);
  const std::int64_t counts[2] = {settings_.substeps, settings_.constraint_iterations};
  h = fnv1a64(counts, sizeof counts, h);
  h = fnv1a64(&settings_.dt, sizeof settings_.dt, h);
  if (impulses) {  // the impulse stage's sweeps and substeps (not hashed before they existed)
    const std::int64_t stage[2] = {settings_.impulse_iterations, settings_.impulse_substeps};
    h = fnv1a64(stage, sizeof stage, h);
  }
  const auto add = [&h](const auto& v) { h = fnv1a64(v.data(), v.size() * sizeof(v[0]), h); };
  add(plocal);
  add(pbody);
  add(pmat);
  add(binertia);
  add(rigid_first_);
  add(laws);
  add(planes);
  add(colouring.constraints);
  add(colour_first_);
  add(soft.clusters);
  add(soft.members);
  add(gather);
  add(exclusions);
  for (const auto& [body, q] : sphere_turns_) {
    h = fnv1a64(&body, sizeof body, h);
    h = fnv1a64(&q, sizeof q, h);
  }
  std::uint64_t w = fnv1a64(nullptr, 0);
  for (std::size_t i = 0; i < ppos.size(); ++i) {
    const float pair[2] = {ppos[i].w, pvel[i].w};
    w = fnv1a64(pair, sizeof pair, w);
  }
  particle_w_hash_ = w;
  setup_hash_ = fnv1a64(&w, sizeof w, h);

  const std::uint32_t neighbour_state[4] = {1u, 0u, 0u, 0u};  // build at the first step
  Status s = d.allocate(sizes_);
  if (s) s = write_vector(d, Buffer::ParticlePos, ppos);
  if (s) s = write_vector(d, Buffer::ParticleVel, pvel);
  if (s) s = write_vector(d, Buffer::ParticleLocal, plocal);
  if (s) s = write_vector(d, Buffer::ParticleBody, pbody);
  if (s) s = write_vector(d, Buffer::ParticleMaterial, pmat);
  if (s) s = write_vector(d, Buffer::BodyPos, bpos);
  if (s) s = write_vector(d, Buffer::BodyQuat, bquat);
  if (s) s = write_vector(d, Buffer::BodyVel, bvel);
  if (s) s = write_vector(d, Buffer::BodyAngMom, bangmom);
  if (s) s = write_vector(d, Buffer::BodyAngVel, bangvel);
  if (s) s = write_vector(d, Buffer::BodyInvInertia, binertia);
  rigid_inv_inertia_ = binertia;
  if (s) s = write_vector(d, Buffer::BodyFirst, rigid_first_);
  if (s) s = write_vector(d, Buffer::NeighbourRefPos, ppos);
  if (s) s = d.write(Buffer::NeighbourState, neighbour_state, sizeof neighbour_state);
  if (s) s = write_vector(d, Buffer::ContactLaws, laws);
  if (s) s = write_vector(d, Buffer::Planes, planes);
  if (s) s = write_vector(d, Buffer::Constraints, colouring.constraints);
  if (s) s = write_vector(d, Buffer::Clusters, soft.clusters);
  if (s) s = write_vector(d, Buffer::ClusterMembers, soft.members);
  if (s) s = write_vector(d, Buffer::ClusterFrames, frames);
  if (s) s = write_vector(d, Buffer::ClusterGather, gather);
  if (s) s = write_vector(d, Buffer::LinkExclusions, exclusions);
  if (s) s = write_vector(d, Buffer::HaloIndex, halo_index);
  if (s && sizes_.partition != 0) s = write_vector(d, Buffer::PartitionRefPos, ppos);
  if (s) s = clear_contact_history();
  if (!s) return s;
  // The energy guard: the scene's model, and the reference point potential energy is measured
  // from, the lowest particle along gravity (the first without gravity), so that the device's
  // float energies stay precise wherever the scene is.
  energy_model_ = motes::energy_model(scene);
  rigid_scene_body_.assign(sizes_.bodies, 0u);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    if (!info.free_sphere && !info.linked && !info.soft) {
      rigid_scene_body_[device_index_[b]] = static_cast<std::uint32_t>(b);
    }
  }
  std::size_t lowest = 0;
  for (std::size_t i = 1; i < ppos.size(); ++i) {
    const auto g_dot = [&](const vec4& x) {
      return settings_.gravity.dot(Eigen::Vector3f(x.x, x.y, x.z).cast<double>());
    };
    if (g_dot(ppos[i]) > g_dot(ppos[lowest])) lowest = i;
  }
  const vec4 origin = ppos.empty() ? vec4(0.0f) : ppos[lowest];
  energy_origin_ = Eigen::Vector3f(origin.x, origin.y, origin.z).cast<double>();
  const std::uint32_t header[MOTES_ENERGY_HEADER] = {
      shared::float_bits(origin.x), shared::float_bits(origin.y), shared::float_bits(origin.z), 0u};
  if (Status st = d.write(Buffer::EnergyPartials, header, sizeof header); !st) return st;
  energy_started_ = false;
  // Rigid particles take their pose from the bodies with the device's own arithmetic.
  if (sizes_.rigid_particles > 0) d.enqueue(Kernel::ParticlesUpdate, params_);
  return d.synchronize();
}

Status Simulation::step(std::uint64_t count) {
  Device& d = *device_;
  const bool rigid = sizes_.bodies > 0;
  const bool free = sizes_.particles > sizes_.rigid_particles;
  // A list build moves the impulse contacts' memory on (ImpulseStamp) only when the setting asks.
  shared::StepParams lists = params_;
  if (!settings_.impulse_memory_across_builds) lists.flags &= ~MOTES_FLAG_IMPULSE;
  for (std::uint64_t k = 0; k < count; ++k) {
    for (int sub = 0; sub < settings_.substeps; ++sub) {
      d.enqueue(Kernel::NeighboursUpdate, lists);
      d.enqueue(Kernel::ContactsCompute, params_);
      if (rigid && sizes_.impulse != 0) {
        step_impulses();
      } else if (rigid) {
        d.enqueue(Kernel::BodiesReduce, params_);
        d.enqueue(Kernel::BodiesIntegrate, params_);
        d.enqueue(Kernel::ParticlesUpdate, params_);
      }
      if (free) d.enqueue(Kernel::ParticlesIntegrate, params_);
      if (params_.cluster_count > 0) {
        d.enqueue(Kernel::ClustersFit, params_);
        d.enqueue(Kernel::ClustersGoal, params_);
      }
      for (int it = 0; it < settings_.constraint_iterations && colour_first_.size() > 1; ++it) {
        for (std::size_t c = 0; c + 1 < colour_first_.size(); ++c) {
          shared::StepParams colour = params_;
          // Only the last sweep's positions are the ones the next contacts see.
          if (it + 1 == settings_.constraint_iterations) colour.flags |= MOTES_FLAG_SKIN_CHECK;
          colour.constraint_first = colour_first_[c];
          colour.constraint_count = colour_first_[c + 1] - colour_first_[c];
          d.enqueue(Kernel::ConstraintsSolve, colour);
        }
      }
      if (sizes_.absorb != 0) absorb_attachments();
    }
    ++steps_;
    time_ = static_cast<double>(steps_) * settings_.dt;
  }
  return d.synchronize();
}

void Simulation::absorb_attachments() {
  // Cloth and ropes attached to rigid bodies: the constraints moved the bodies' particles too; each
  // body takes what they did as an impulse (shared/body_math.h: particle_absorbed_impulse), summed
  // over its particles in order (impulses_apply), and its particles follow its pose again.
  Device& d = *device_;
  shared::StepParams absorb = params_;
  absorb.flags = (absorb.flags | MOTES_FLAG_ABSORB) & ~MOTES_FLAG_IMPULSE_COUNT;
  shared::StepParams apply = params_;
  apply.flags = (apply.flags | MOTES_FLAG_ABSORB) & ~MOTES_FLAG_IMPULSE_COUNT;
  d.enqueue(Kernel::ParticlesUpdate, absorb);
  d.enqueue(Kernel::ImpulsesApply, apply);
  d.enqueue(Kernel::ParticlesUpdate, params_);
}

void Simulation::step_impulses() {
  // Forces (soft bodies, cloth, ropes) are summed once; then the impulse stage runs its own
  // substeps on the contacts the lists hold (docs/architecture.md, "Impulse contacts"). Each:
  // gravity and forces into the velocities; the counting pass (every contact in reach counted,
  // the start velocities kept, the warm start applied); sweeps with position correction, the
  // velocities they leave kept for the pose; relaxing sweeps without it, whose velocities the
  // bodies keep; the pose; the particles follow.
  Device& d = *device_;
  const int substeps = settings_.impulse_substeps;
  const int sweeps = (settings_.impulse_iterations + substeps - 1) / substeps;
  // The first half of the sweeps with the position correction, the rest without it: the
  // velocities the bodies keep converge further and carry no push-out speed (docs/architecture.md,
  // "Impulse contacts").
  const int correcting = (sweeps + 1) / 2;
  const int relaxing = sweeps - correcting;
  shared::StepParams sub = params_;
  sub.gravity_dt.w = params_.gravity_dt.w / static_cast<float>(substeps);
  shared::StepParams velocity = sub;
  velocity.flags |= MOTES_FLAG_BODY_VELOCITY;
  shared::StepParams count = sub;
  count.flags |= MOTES_FLAG_IMPULSE_COUNT;
  shared::StepParams last = sub;  // the last correcting sweep keeps its velocities for the pose
  if (relaxing > 0) last.flags |= MOTES_FLAG_IMPULSE_PUSH;
  shared::StepParams relax = sub;
  relax.flags |= MOTES_FLAG_IMPULSE_RELAX;
  shared::StepParams pose = last;
  pose.flags |= MOTES_FLAG_BODY_POSE;
  d.enqueue(Kernel::BodiesReduce, params_);
  for (int s = 0; s < substeps; ++s) {
    d.enqueue(Kernel::BodiesIntegrate, velocity);
    d.enqueue(Kernel::ImpulsesCompute, count);
    d.enqueue(Kernel::ImpulsesApply, count);
    for (int it = 0; it < correcting; ++it) {
      d.enqueue(Kernel::ImpulsesCompute, sub);
      d.enqueue(Kernel::ImpulsesApply, it + 1 == correcting ? last : sub);
    }
    for (int it = 0; it < relaxing; ++it) {
      d.enqueue(Kernel::ImpulsesCompute, relax);
      d.enqueue(Kernel::ImpulsesApply, relax);
    }
    d.enqueue(Kernel::BodiesIntegrate, pose);
    d.enqueue(Kernel::ParticlesUpdate, sub);
  }
}

Status Simulation::clear_contact_history() {
  if (sizes_.impulse == 0) return Status::ok();
  Device& d = *device_;
  const std::vector<vec4> acc(buffer_layout(Buffer::ContactImpulse, sizes_).count, vec4(0.0f));
  const std::vector<std::uint32_t> stamp(sizes_.rigid_particles, 0u);
  Status s = write_vector(d, Buffer::ContactImpulse, acc);
  if (s) s = write_vector(d, Buffer::ImpulseStamp, stamp);
  return s;
}

Result<Snapshot> Simulation::snapshot() {
  Device& d = *device_;
  const std::size_t n = sizes_.particles;
  const std::size_t nb = sizes_.bodies;
  std::vector<vec4> ppos, pvel, bpos, bquat, bvel, bangmom, bangvel;
  Status st = read_vector(d, Buffer::ParticlePos, ppos, n);
  if (st) st = read_vector(d, Buffer::ParticleVel, pvel, n);
  if (st) st = read_vector(d, Buffer::BodyPos, bpos, nb);
  if (st) st = read_vector(d, Buffer::BodyQuat, bquat, nb);
  if (st) st = read_vector(d, Buffer::BodyVel, bvel, nb);
  if (st) st = read_vector(d, Buffer::BodyAngMom, bangmom, nb);
  if (st) st = read_vector(d, Buffer::BodyAngVel, bangvel, nb);
  std::vector<shared::ClusterFrame> frames;
  if (st) st = read_vector(d, Buffer::ClusterFrames, frames, sizes_.clusters);
  if (!st) return st;

  Snapshot s;
  s.cluster_rotation.reserve(frames.size());
  for (const shared::ClusterFrame& f : frames) s.cluster_rotation.push_back(f.rotation);
  s.time = time_;
  s.step = steps_;
  const std::size_t scene_bodies = bodies_.size();
  s.particle_pos.resize(n);
  s.particle_vel.resize(n);
  s.particle_body.resize(n);
  s.body_pos.resize(scene_bodies);
  s.body_quat.assign(scene_bodies, vec4(0.0f, 0.0f, 0.0f, 1.0f));
  s.body_vel.resize(scene_bodies);
  s.body_angmom.resize(scene_bodies);
  s.body_angvel.resize(scene_bodies);
  for (std::size_t b = 0; b < scene_bodies; ++b) {
    const BodyInfo& info = bodies_[b];
    const std::uint32_t at = device_index_[b];
    const std::uint32_t first =
        info.free_sphere || info.linked || info.soft ? at : rigid_first_[at];
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      s.particle_pos[info.first_particle + k] = ppos[first + k];
      s.particle_vel[info.first_particle + k] = pvel[first + k];
      s.particle_body[info.first_particle + k] = static_cast<std::uint32_t>(b);
    }
    if (info.linked || info.soft) {  // the mean of its particles, in double
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (std::uint32_t k = 0; k < info.particle_count; ++k) {
        const vec4 p = ppos[first + k];
        const vec4 u = pvel[first + k];
        x += Eigen::Vector3f(p.x, p.y, p.z).cast<double>();
        v += Eigen::Vector3f(u.x, u.y, u.z).cast<double>();
      }
      const double count = static_cast<double>(info.particle_count);
      s.body_pos[b] = to_vec4(x / count, 1.0 / info.mass);
      s.body_vel[b] = to_vec4(v / count, 0.0);
      s.body_angmom[b] = vec4(0.0f);
      s.body_angvel[b] = vec4(0.0f);
      continue;
    }
    if (info.free_sphere) {
      const vec4 p = ppos[at];
      const vec4 v = pvel[at];
      s.body_pos[b] = vec4(p.x, p.y, p.z, v.w);  // a one-particle body's inverse mass
      s.body_vel[b] = vec4(v.x, v.y, v.z, 0.0f);
      s.body_angmom[b] = vec4(0.0f);
      s.body_angvel[b] = vec4(0.0f);
      continue;
    }
    s.body_pos[b] = bpos[at];
    s.body_quat[b] = bquat[at];
    s.body_vel[b] = bvel[at];
    s.body_angmom[b] = bangmom[at];
    s.body_angvel[b] = bangvel[at];
  }
  for (const auto& [b, q] : sphere_turns_) s.body_quat[b] = q;
  return s;
}

Status Simulation::write_state(const Snapshot& state) {
  const std::size_t n = sizes_.particles;
  const std::size_t nb = bodies_.size();
  if (state.particle_pos.size() != n || state.particle_vel.size() != n ||
      state.body_pos.size() != nb || state.body_quat.size() != nb || state.body_vel.size() != nb ||
      state.body_angmom.size() != nb || state.body_angvel.size() != nb) {
    return Status::error(fmt::format(
        "write_state: a state of {} particles and {} bodies for a simulation of {} and {}",
        state.particle_pos.size(), state.body_pos.size(), n, nb));
  }
  if (Status s = restore(state, false); !s) return s;
  steps_ = state.step;
  time_ = static_cast<double>(steps_) * settings_.dt;
  rebase_energy();  // a state from outside: the energy guard measures from it
  return Status::ok();
}

namespace {

/// ContactImpulse's slot of rigid device particle i with plane q (Buffer::ContactImpulse).
std::size_t plane_slot(const Sizes& sizes, std::uint32_t i, std::uint32_t q) {
  return (std::size_t{sizes.neighbour_capacity} + q) * sizes.rigid_particles + i;
}

}  // namespace

Status Simulation::read_plane_impulses(Snapshot& state) {
  state.plane_impulse.clear();
  if (sizes_.impulse == 0 || sizes_.planes == 0) return Status::ok();
  std::vector<vec4> acc;
  if (Status s = read_vector(*device_, Buffer::ContactImpulse, acc,
                             buffer_layout(Buffer::ContactImpulse, sizes_).count);
      !s) {
    return s;
  }
  state.plane_impulse.assign(std::size_t{sizes_.particles} * sizes_.planes, vec4(0.0f));
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    if (info.free_sphere || info.linked || info.soft) continue;
    const std::uint32_t first = rigid_first_[device_index_[b]];
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      for (std::uint32_t q = 0; q < sizes_.planes; ++q) {
        state.plane_impulse[(std::size_t{info.first_particle} + k) * sizes_.planes + q] =
            acc[plane_slot(sizes_, first + k, q)];
      }
    }
  }
  return Status::ok();
}

Status Simulation::restore(const Snapshot& state, bool rebuild) {
  Device& d = *device_;
  const std::size_t n = sizes_.particles;
  const std::size_t nb = sizes_.bodies;
  std::vector<vec4> ppos(n), pvel(n), bpos(nb), bquat(nb), bvel(nb), bangmom(nb), bangvel(nb);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    const std::uint32_t at = device_index_[b];
    const std::uint32_t first =
        info.free_sphere || info.linked || info.soft ? at : rigid_first_[at];
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      ppos[first + k] = state.particle_pos[info.first_particle + k];
      pvel[first + k] = state.particle_vel[info.first_particle + k];
    }
    if (info.free_sphere || info.linked || info.soft) continue;
    bpos[at] = state.body_pos[b];
    bquat[at] = state.body_quat[b];
    bvel[at] = state.body_vel[b];
    bangmom[at] = state.body_angmom[b];
    bangvel[at] = state.body_angvel[b];
  }
  const std::uint32_t neighbour_state[4] = {1u, 0u, 0u, 0u};  // rebuild at the next step
  Status s = write_vector(d, Buffer::ParticlePos, ppos);
  if (s) s = write_vector(d, Buffer::ParticleVel, pvel);
  if (s) s = write_vector(d, Buffer::BodyPos, bpos);
  if (s) s = write_vector(d, Buffer::BodyQuat, bquat);
  if (s) s = write_vector(d, Buffer::BodyVel, bvel);
  if (s) s = write_vector(d, Buffer::BodyAngMom, bangmom);
  if (s) s = write_vector(d, Buffer::BodyAngVel, bangvel);
  if (s && !rebuild && sizes_.partition != 0) s = write_vector(d, Buffer::PartitionRefPos, ppos);
  if (s && rebuild) s = d.write(Buffer::NeighbourState, neighbour_state, sizeof neighbour_state);
  if (s && rebuild) s = clear_contact_history();
  if (s && sizes_.impulse != 0 && sizes_.planes > 0 &&
      state.plane_impulse.size() == std::size_t{n} * sizes_.planes) {
    std::vector<vec4> acc;
    s = read_vector(d, Buffer::ContactImpulse, acc,
                    buffer_layout(Buffer::ContactImpulse, sizes_).count);
    for (std::size_t b = 0; s && b < bodies_.size(); ++b) {
      const BodyInfo& info = bodies_[b];
      if (info.free_sphere || info.linked || info.soft) continue;
      const std::uint32_t first = rigid_first_[device_index_[b]];
      for (std::uint32_t k = 0; k < info.particle_count; ++k) {
        for (std::uint32_t q = 0; q < sizes_.planes; ++q) {
          acc[plane_slot(sizes_, first + k, q)] =
              state.plane_impulse[(std::size_t{info.first_particle} + k) * sizes_.planes + q];
        }
      }
    }
    if (s) s = write_vector(d, Buffer::ContactImpulse, acc);
  }
  if (s && state.cluster_rotation.size() == sizes_.clusters && sizes_.clusters > 0) {
    std::vector<shared::ClusterFrame> frames;
    s = read_vector(d, Buffer::ClusterFrames, frames, sizes_.clusters);
    for (std::size_t k = 0; s && k < frames.size(); ++k) {
      frames[k].rotation = state.cluster_rotation[k];
    }
    if (s) s = write_vector(d, Buffer::ClusterFrames, frames);
  }
  if (!s) return s;
  return d.synchronize();
}

Status Simulation::set_body_velocities(const std::vector<Eigen::Vector3d>& velocity,
                                       const std::vector<Eigen::Vector3d>& angular) {
  const std::size_t count = bodies_.size();
  if (velocity.size() != count || (!angular.empty() && angular.size() != count)) {
    return Status::error(
        fmt::format("set_body_velocities: {} velocities and {} angular velocities for {} bodies",
                    velocity.size(), angular.size(), count));
  }
  for (std::size_t b = 0; b < count; ++b) {
    const bool moving = !velocity[b].isZero(0.0) || (!angular.empty() && !angular[b].isZero(0.0));
    if (!velocity[b].allFinite() || (!angular.empty() && !angular[b].allFinite())) {
      return Status::error(fmt::format("set_body_velocities: body {} '{}': not a finite velocity",
                                       b, bodies_[b].name));
    }
    if (bodies_[b].kind == BodyKind::Static && moving) {
      return Status::error(
          fmt::format("set_body_velocities: body {} '{}' is static: its velocity stays zero", b,
                      bodies_[b].name));
    }
    if ((bodies_[b].free_sphere || bodies_[b].linked) && !angular.empty() &&
        !angular[b].isZero(0.0)) {
      return Status::error(fmt::format(
          "set_body_velocities: body {} '{}' is a {}, which has no angular velocity of its own: "
          "give its particles velocities instead",
          b, bodies_[b].name, bodies_[b].linked ? "cloth or rope" : "free sphere"));
    }
  }
  Result<Snapshot> snap = snapshot();
  if (!snap) return snap.status();
  Snapshot& state = snap.value();
  for (std::size_t b = 0; b < count; ++b) {
    const BodyInfo& info = bodies_[b];
    const vec4 v = to_vec4(velocity[b], 0.0);
    if (info.free_sphere || info.linked || info.soft) {  // every particle that is not pinned
      // A soft body turns about the mean of its particles: v + w x (x - mean).
      const vec4 mean = state.body_pos[b];
      const Eigen::Vector3d w =
          info.soft && !angular.empty() ? angular[b] : Eigen::Vector3d::Zero();
      for (std::uint32_t k = info.first_particle; k < info.first_particle + info.particle_count;
           ++k) {
        const vec4 old = state.particle_vel[k];
        const vec4 x = state.particle_pos[k];
        const Eigen::Vector3d r =
            Eigen::Vector3f(x.x - mean.x, x.y - mean.y, x.z - mean.z).cast<double>();
        const vec4 spin = to_vec4(velocity[b] + w.cross(r), 0.0);
        if (old.w != 0.0f) state.particle_vel[k] = vec4(spin.x, spin.y, spin.z, old.w);
      }
      continue;
    }
    state.body_vel[b] = v;
    if (angular.empty()) continue;
    // L = R diag(I) R^T w, in double, with the moments the body was uploaded with.
    const vec4 q = state.body_quat[b];
    const Eigen::Matrix3d rot =
        Eigen::Quaternionf(q.w, q.x, q.y, q.z).cast<double>().normalized().toRotationMatrix();
    const vec4 inv = rigid_inv_inertia_[device_index_[b]];
    const auto moment = [](float inverse) {
      return inverse > 0.0f ? 1.0 / static_cast<double>(inverse) : 0.0;
    };
    const Eigen::Vector3d moments(moment(inv.x), moment(inv.y), moment(inv.z));
    state.body_angvel[b] = to_vec4(angular[b], 0.0);
    state.body_angmom[b] = to_vec4(rot * moments.asDiagonal() * rot.transpose() * angular[b], 0.0);
  }
  if (Status s = restore(state); !s) return s;
  // The rigid particles' velocities from their bodies' new motion.
  if (sizes_.rigid_particles > 0) device_->enqueue(Kernel::ParticlesUpdate, params_);
  rebase_energy();  // energy from outside the scene: the energy guard measures from here
  return device_->synchronize();
}

Result<NeighbourStats> Simulation::neighbour_stats() {
  std::uint32_t words[4] = {};
  if (Status s = device_->read(Buffer::NeighbourState, words, sizeof words); !s) return s;
  NeighbourStats out;
  out.builds = words[MOTES_NEIGHBOUR_BUILDS];
  out.over_capacity = words[MOTES_NEIGHBOUR_OVER_CAPACITY];
  out.max_count = words[MOTES_NEIGHBOUR_MAX_COUNT];
  out.rebuild_pending = words[MOTES_NEIGHBOUR_REBUILD] != 0;
  return out;
}

void Simulation::queue_halo_pack() {
  shared::StepParams p = params_;
  p.halo_particles = halo_entries_[0];
  p.halo_bodies = halo_entries_[1];
  p.halo_first = 0;
  device_->enqueue(Kernel::HaloPack, p);
}

void Simulation::queue_halo_unpack() {
  shared::StepParams p = params_;
  p.halo_particles = halo_entries_[2];
  p.halo_bodies = halo_entries_[3];
  p.halo_first = halo_entries_[0] + halo_entries_[1];
  device_->enqueue(Kernel::HaloUnpack, p);
}

Status Simulation::halo_pack() {
  if (halo_out_count_ == 0) return device_->synchronize();
  queue_halo_pack();
  return device_->read(Buffer::HaloData, halo_out_.get(), halo_out_count_ * sizeof(vec4));
}

Status Simulation::halo_unpack() {
  if (halo_in_count_ == 0) return Status::ok();
  if (Status s = device_->write(Buffer::HaloData, halo_in_.get(), halo_in_count_ * sizeof(vec4));
      !s) {
    return s;
  }
  queue_halo_unpack();
  return Status::ok();
}

Result<std::vector<unsigned char>> Simulation::share_halo() {
  return device_->share_halo_outbox(std::max<std::size_t>(halo_out_count_, 1) * sizeof(vec4));
}

Status Simulation::halo_pack_direct() {
  if (halo_out_count_ == 0) return device_->synchronize();
  queue_halo_pack();
  if (Status s = device_->publish_halo_outbox(halo_out_count_ * sizeof(vec4)); !s) return s;
  return device_->synchronize();
}

Result<std::size_t> Simulation::open_peer_halo(const std::vector<unsigned char>& handle) {
  return device_->open_peer_outbox(handle);
}

Status Simulation::halo_unpack_direct(std::span<const HaloFetch> fetches) {
  if (halo_in_count_ == 0) return Status::ok();
  for (const HaloFetch& f : fetches) {
    if (f.to + f.count > halo_in_count_) {
      return Status::error(fmt::format("halo_unpack_direct: vec4s [{}, {}) of a halo of {}", f.to,
                                       f.to + f.count, halo_in_count_));
    }
    if (Status s = device_->fetch_peer_outbox(f.peer, f.from * sizeof(vec4), f.to * sizeof(vec4),
                                              f.count * sizeof(vec4));
        !s) {
      return s;
    }
  }
  queue_halo_unpack();
  return Status::ok();
}

Status Simulation::request_rebuild() {
  const std::uint32_t rebuild = 1;  // the first word, MOTES_NEIGHBOUR_REBUILD
  static_assert(MOTES_NEIGHBOUR_REBUILD == 0u);
  return device_->write(Buffer::NeighbourState, &rebuild, sizeof rebuild);
}

Result<double> Simulation::partition_displacement() {
  if (sizes_.partition == 0) {
    return Status::error("partition_displacement: a simulation without a partition reference");
  }
  device_->enqueue(Kernel::ParticlesDisplacement, params_);
  std::uint32_t bits = 0;
  if (Status s = device_->read(Buffer::PartitionCheck, &bits, sizeof bits); !s) return s;
  if (bits >= MOTES_PARTITION_NOT_FINITE) return std::numeric_limits<double>::infinity();
  return std::sqrt(static_cast<double>(std::bit_cast<float>(bits)));
}

namespace {

template <typename T>
void fnv1a(std::uint64_t& h, const std::vector<T>& v) {
  const auto* p = reinterpret_cast<const unsigned char*>(v.data());
  for (std::size_t i = 0; i < v.size() * sizeof(T); ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
}

bool finite(const vec4& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

}  // namespace

Result<std::uint64_t> Simulation::state_hash() {
  Result<Snapshot> s = snapshot();
  if (!s) return s.status();
  std::uint64_t h = 14695981039346656037ull;
  fnv1a(h, s->particle_pos);
  fnv1a(h, s->particle_vel);
  fnv1a(h, s->body_pos);
  fnv1a(h, s->body_quat);
  fnv1a(h, s->body_vel);
  fnv1a(h, s->body_angmom);
  return h;
}

Status Simulation::check_finite() {
  Result<Snapshot> s = snapshot();
  if (!s) return s.status();
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const bool ok = finite(s->body_pos[b]) && finite(s->body_quat[b]) && finite(s->body_vel[b]) &&
                    finite(s->body_angmom[b]);
    std::uint32_t bad_particle = std::numeric_limits<std::uint32_t>::max();
    const BodyInfo& info = bodies_[b];
    for (std::uint32_t i = info.first_particle; i < info.first_particle + info.particle_count;
         ++i) {
      if (!finite(s->particle_pos[i]) || !finite(s->particle_vel[i])) {
        bad_particle = i;
        break;
      }
    }
    if (!ok || bad_particle != std::numeric_limits<std::uint32_t>::max()) {
      const vec4 p = s->body_pos[b];
      return Status::error(fmt::format(
          "non-finite state at step {} (t = {} s): body {} '{}' position ({}, {}, {}){}; the "
          "time step is probably too large for the contact stiffness",
          steps_, time_, b, info.name, p.x, p.y, p.z,
          bad_particle == std::numeric_limits<std::uint32_t>::max()
              ? std::string()
              : fmt::format(", particle {}", bad_particle)));
    }
  }
  return Status::ok();
}

}  // namespace motes
