// The scene's bodies laid out for the device (scene_layout.h): one builder per kind (rigid
// bodies, free spheres, soft bodies), called in the scene's order.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <new>
#include <numbers>

#include "motes/shapes.h"
#include "scene_layout.h"

namespace motes::layout {
namespace {

using shared::vec4;

vec4 to_quat(const Eigen::Quaterniond& q) {
  return {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()),
          static_cast<float>(q.w())};
}

/// One body as every kind's builder needs it: its scene index, its shape's mass properties, and
/// its pose.
struct Placement {
  std::size_t index = 0;  ///< in the scene's bodies
  const BodySpec& spec;
  const MassProperties& mp;
  bool dynamic = false;
  /// Body frame = principal axes: orientation = rotation * (principal -> shape frame).
  Eigen::Quaterniond orient;
  Eigen::Matrix3d to_body;  ///< shape frame to body frame
  Eigen::Matrix3d rot;      ///< orient as a matrix
  Eigen::Vector3d vel;      ///< zero for a static body
  double radius = 0.0;
  double inv_pm = 0.0;  ///< inverse particle mass (0: static)
};

/// The next device particle of each kind: rigid [0, Nr), free spheres [Nr, Ns), soft [Ns, Nl).
struct Cursor {
  std::uint32_t rigid = 0;
  std::uint32_t free = 0;
  std::uint32_t soft_first = 0;
  std::uint32_t soft = 0;
  std::uint32_t soft_bodies = 0;  ///< so far
};

Placement place(std::size_t index, const BodySpec& spec, const MassProperties& mp) {
  const bool dynamic = spec.kind == BodyKind::Dynamic;
  const Eigen::Quaterniond orient = (spec.rotation.normalized() * mp.principal_frame).normalized();
  return {index,
          spec,
          mp,
          dynamic,
          orient,
          mp.principal_frame.toRotationMatrix().transpose(),
          orient.toRotationMatrix(),
          dynamic ? spec.velocity : Eigen::Vector3d::Zero(),
          0.5 * spec.shape->diameter,
          dynamic ? 1.0 / mp.particle_mass : 0.0};
}

/// A rigid body: its body state, its particles' offsets in the body frame, and their positions
/// (particles_update recomputes positions and velocities on the device after the upload).
void build_rigid_body(const Placement& body, Cursor& at, HostLayout& out) {
  const BodySpec& spec = body.spec;
  const MassProperties& mp = body.mp;
  RigidLayout& rigid = out.rigid;
  ParticleLayout& p = out.particles;
  const auto b = static_cast<std::uint32_t>(rigid.first.size());
  out.device_index[body.index] = b;
  rigid.first.push_back(at.rigid);
  const Eigen::Vector3d inv_moments = mp.principal_moments.cwiseInverse();
  const Eigen::Vector3d omega = body.dynamic ? spec.angular_velocity : Eigen::Vector3d::Zero();
  const Eigen::Vector3d angmom =
      body.rot * mp.principal_moments.asDiagonal() * body.rot.transpose() * omega;
  rigid.pos.push_back(to_vec4(spec.position, body.dynamic ? 1.0 / mp.mass : 0.0));
  rigid.quat.push_back(to_quat(body.orient));
  rigid.vel.push_back(to_vec4(body.vel, 0.0));
  rigid.angmom.push_back(to_vec4(angmom, 0.0));
  rigid.angvel.push_back(to_vec4(omega, 0.0));
  rigid.inv_inertia.push_back(body.dynamic ? to_vec4(inv_moments, 0.0) : vec4(0.0f));
  for (const Eigen::Vector3f& pt : spec.shape->points) {
    const Eigen::Vector3d local = body.to_body * (pt.cast<double>() - mp.center);
    const std::uint32_t i = at.rigid++;
    rigid.local.push_back(to_vec4(local, 0.0));
    p.pos[i] = to_vec4(spec.position + body.rot * local, body.radius);
    p.vel[i] = to_vec4(Eigen::Vector3d::Zero(), body.inv_pm);
    p.body[i] = b;
    p.material[i] = static_cast<std::uint32_t>(spec.material);
  }
}

/// A free sphere: the particle is the body, its state is the body's; it never turns (its
/// orientation is kept on the host when it is not the identity).
void build_free_sphere(const Placement& body, Cursor& at, HostLayout& out) {
  const BodySpec& spec = body.spec;
  ParticleLayout& p = out.particles;
  const std::uint32_t i = at.free++;
  out.device_index[body.index] = i;
  const vec4 q = to_quat(body.orient);
  if (q.x != 0.0f || q.y != 0.0f || q.z != 0.0f || q.w != 1.0f) {
    out.sphere_turns.emplace_back(static_cast<std::uint32_t>(body.index), q);
  }
  const Eigen::Vector3d local =
      body.to_body * (spec.shape->points[0].cast<double>() - body.mp.center);
  p.pos[i] = to_vec4(spec.position + body.rot * local, body.radius);
  p.vel[i] = to_vec4(body.vel, body.inv_pm);
  p.body[i] = out.sizes.bodies + (i - out.sizes.rigid_particles);
  p.material[i] = static_cast<std::uint32_t>(spec.material);
}

/// A soft body: free particles of one body (no contact among themselves), pulled to their
/// clusters' goals; its clusters are made from the particles' places at the start.
Status build_soft_body(const Scene& scene, const Placement& body, Cursor& at, HostLayout& out) {
  const BodySpec& spec = body.spec;
  const Settings& settings = scene.settings;
  ParticleLayout& p = out.particles;
  out.device_index[body.index] = at.soft;
  std::vector<Eigen::Vector3d> world;
  world.reserve(spec.shape->points.size());
  const std::uint32_t body_word =
      out.sizes.bodies + (at.soft_first - out.sizes.rigid_particles) + at.soft_bodies++;
  for (const Eigen::Vector3f& pt : spec.shape->points) {
    const Eigen::Vector3d offset = body.rot * (body.to_body * (pt.cast<double>() - body.mp.center));
    const std::uint32_t i = at.soft++;
    world.push_back(spec.position + offset);
    p.pos[i] = to_vec4(world.back(), body.radius);
    p.vel[i] = to_vec4(body.vel + spec.angular_velocity.cross(offset), body.inv_pm);
    p.body[i] = body_word;
    p.material[i] = static_cast<std::uint32_t>(spec.material);
  }
  SoftSpec soft_spec = *spec.soft;
  if (soft_spec.frequency > 0.0) {
    const double turn = 2.0 * std::numbers::pi * soft_spec.frequency * settings.dt /
                        static_cast<double>(settings.substeps);
    soft_spec.stiffness = std::min(1.0, turn * turn);
  }
  SoftClusters& clusters = out.soft.clusters;
  BodyInfo& info = out.bodies[body.index];
  info.first_cluster = static_cast<std::uint32_t>(clusters.clusters.size());
  if (Status st = add_soft_body(soft_spec, world, body.mp.particle_mass,
                                settings.dt / static_cast<double>(settings.substeps),
                                out.device_index[body.index], clusters);
      !st) {
    return Status::error(fmt::format("{}: body '{}': {}", scene.source, spec.name, st.message()));
  }
  info.cluster_count = static_cast<std::uint32_t>(clusters.clusters.size()) - info.first_cluster;
  return Status::ok();
}

/// The particle arrays (every particle's, the cloths' and ropes' too) and the bodies' indices.
Status allocate(const Scene& scene, const SceneCounts& counts, HostLayout& out) {
  try {
    out.particles.pos.resize(counts.particles);
    out.particles.vel.resize(counts.particles);
    out.rigid.local.reserve(counts.rigid_particles);
    out.particles.body.resize(counts.particles);
    out.particles.material.resize(counts.particles);
    out.device_index.assign(scene.bodies.size(), 0);
  } catch (const std::bad_alloc&) {
    return Status::error(
        fmt::format("{}: out of host memory for {} particles", scene.source, counts.particles));
  }
  return Status::ok();
}

}  // namespace

Status build_bodies(const Scene& scene, const SceneCounts& counts, HostLayout& out) {
  if (Status st = allocate(scene, counts, out); !st) return st;
  const ParticleSet* last_shape = nullptr;
  int last_material = -1;
  MassProperties mp;
  Cursor at;
  at.free = static_cast<std::uint32_t>(counts.rigid_particles);
  at.soft_first = static_cast<std::uint32_t>(counts.body_particles - counts.soft_particles);
  at.soft = at.soft_first;
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
    const Placement body = place(bi, spec, mp);
    const bool free = is_free_sphere(spec, counts.impulses);
    out.bodies[bi].mass = mp.mass;
    out.bodies[bi].free_sphere = free;
    if (spec.soft) {
      if (Status st = build_soft_body(scene, body, at, out); !st) return st;
    } else if (free) {
      build_free_sphere(body, at, out);
    } else {
      build_rigid_body(body, at, out);
    }
  }
  out.rigid.first.push_back(at.rigid);
  SoftLayout& soft = out.soft;
  soft.gather =
      soft.clusters.clusters.empty() ? std::vector<std::uint32_t>{} : cluster_gather(soft.clusters);
  soft.frames.resize(soft.clusters.clusters.size());
  for (shared::ClusterFrame& f : soft.frames) f.rotation = vec4(0.0f, 0.0f, 0.0f, 1.0f);
  out.sizes.clusters = static_cast<std::uint32_t>(soft.clusters.clusters.size());
  out.sizes.cluster_members = static_cast<std::uint32_t>(soft.clusters.members.size());
  return Status::ok();
}

}  // namespace motes::layout
