// Whole-scene helpers: example scenes, simulations on any device, state copies, the oracle run.
#include "scene_support.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "motes/devices.h"

namespace motes_conf {

namespace {

template <typename T>
motes::Status read_all(motes::Simulation& sim, motes::Buffer b, std::vector<T>& out) {
  const motes::BufferLayout layout = motes::buffer_layout(b, sim.sizes());
  out.resize(layout.count);
  return sim.device().read(b, out.data(), layout.bytes());
}

template <typename T>
motes::Status write_all(motes::Simulation& sim, motes::Buffer b, const std::vector<T>& in) {
  return sim.device().write(b, in.data(), in.size() * sizeof(T));
}

}  // namespace

const motes::Result<motes::Scene>& example_scene(const std::string& name) {
  static std::map<std::string, motes::Result<motes::Scene>> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    const std::string path = std::string(MOTES_SOURCE_DIR) + "/examples/scenes/" + name;
    it = cache.emplace(name, motes::load_scene_file(path)).first;
  }
  return it->second;
}

motes::Scene fast_forward(motes::Scene scene, double seconds) {
  const Eigen::Vector3d g = scene.settings.gravity;
  for (motes::BodySpec& b : scene.bodies) {
    if (b.kind != motes::BodyKind::Dynamic) continue;
    b.position += b.velocity * seconds + 0.5 * g * seconds * seconds;
    b.velocity += g * seconds;
  }
  for (motes::LinkedSpec& l : scene.linked) {
    if (!l.pinned.empty()) continue;
    for (Eigen::Vector3d& x : l.points) x += l.velocity * seconds + 0.5 * g * seconds * seconds;
    l.velocity += g * seconds;
  }
  return scene;
}

motes::Result<std::unique_ptr<motes::Simulation>> simulate(const motes::Scene& scene,
                                                           const std::string& backend, int index) {
  auto device = motes::open_device(backend, index);
  if (!device) return device.status();
  return motes::Simulation::create(scene, std::move(device).value());
}

motes::Status read_state(motes::Simulation& sim, DynamicState& out) {
  motes::Status s = read_all(sim, motes::Buffer::ParticlePos, out.particle_pos);
  if (s) s = read_all(sim, motes::Buffer::ParticleVel, out.particle_vel);
  if (s) s = read_all(sim, motes::Buffer::BodyPos, out.body_pos);
  if (s) s = read_all(sim, motes::Buffer::BodyQuat, out.body_quat);
  if (s) s = read_all(sim, motes::Buffer::BodyVel, out.body_vel);
  if (s) s = read_all(sim, motes::Buffer::BodyAngMom, out.body_angmom);
  if (s) s = read_all(sim, motes::Buffer::BodyAngVel, out.body_angvel);
  if (s) s = read_all(sim, motes::Buffer::ClusterFrames, out.cluster_frames);
  return s;
}

motes::Status write_state(motes::Simulation& sim, const DynamicState& state) {
  motes::Status s = write_all(sim, motes::Buffer::ParticlePos, state.particle_pos);
  if (s) s = write_all(sim, motes::Buffer::ParticleVel, state.particle_vel);
  if (s) s = write_all(sim, motes::Buffer::BodyPos, state.body_pos);
  if (s) s = write_all(sim, motes::Buffer::BodyQuat, state.body_quat);
  if (s) s = write_all(sim, motes::Buffer::BodyVel, state.body_vel);
  if (s) s = write_all(sim, motes::Buffer::BodyAngMom, state.body_angmom);
  if (s) s = write_all(sim, motes::Buffer::BodyAngVel, state.body_angvel);
  if (s) s = write_all(sim, motes::Buffer::ClusterFrames, state.cluster_frames);
  return s;
}

void OracleRun::step(std::uint64_t steps) {
  for (std::uint64_t k = 0; k < steps; ++k) {
    for (int sub = 0; sub < substeps; ++sub) {
      motes_ref::step(particles, bodies, laws, planes, params);
      if (!clusters.empty()) {
        motes_ref::clusters_fit(particles.pos, particles.vel, clusters, members, frames);
        motes_ref::clusters_goal(particles, members, frames, params);
      }
      for (int it = 0; it < iterations; ++it) {
        for (std::size_t c = 0; c + 1 < colour_first.size(); ++c) {
          StepParams colour = params;
          colour.constraint_first = colour_first[c];
          colour.constraint_count = colour_first[c + 1] - colour_first[c];
          motes_ref::constraints_solve(particles, constraints, colour);
        }
      }
      if (absorb) {
        motes_ref::ImpulseState s;
        motes_ref::absorbed_impulses(bodies, particles, s.impulse, s.moment);
        StepParams apply = params;
        apply.flags &= ~MOTES_FLAG_IMPULSE_COUNT;
        motes_ref::impulses_apply(bodies, apply, s);
        motes_ref::particles_update(bodies, particles, params);
      }
    }
  }
}

/// The pairs of a cloth made from a mesh that never touch, found from the constraints (not from
/// the simulation's LinkExclusions): two of its particles joined by a path of at most two
/// constraints between its own particles.
std::set<std::pair<uint, uint>> mesh_never_touch(
    const std::vector<uint>& body, const std::vector<motes::shared::Constraint>& constraints) {
  const auto mesh_pair = [&](uint a, uint b) {
    return (body[a] & MOTES_LINKED_MESH_BIT) != 0 && (body[a] >> 20) == (body[b] >> 20);
  };
  std::map<uint, std::vector<uint>> next;
  for (const motes::shared::Constraint& c : constraints) {
    if (c.a < body.size() && c.b < body.size() && mesh_pair(c.a, c.b)) {
      next[c.a].push_back(c.b);
      next[c.b].push_back(c.a);
    }
  }
  std::set<std::pair<uint, uint>> out;
  for (const auto& [a, near] : next) {
    for (const uint b : near) {
      out.insert({a, b});
      for (const uint c : next[b]) {
        if (c != a) out.insert({a, c});
      }
    }
  }
  return out;
}

motes::Status capture(motes::Simulation& sim, OracleRun& out) {
  motes::Status s = read_all(sim, motes::Buffer::ParticlePos, out.particles.pos);
  if (s) s = read_all(sim, motes::Buffer::ParticleVel, out.particles.vel);
  if (s) s = read_all(sim, motes::Buffer::ParticleLocal, out.particles.local);
  if (s) s = read_all(sim, motes::Buffer::ParticleBody, out.particles.body);
  if (s) s = read_all(sim, motes::Buffer::ParticleMaterial, out.particles.material);
  if (s) s = read_all(sim, motes::Buffer::BodyPos, out.bodies.pos);
  if (s) s = read_all(sim, motes::Buffer::BodyQuat, out.bodies.quat);
  if (s) s = read_all(sim, motes::Buffer::BodyVel, out.bodies.vel);
  if (s) s = read_all(sim, motes::Buffer::BodyAngMom, out.bodies.angmom);
  if (s) s = read_all(sim, motes::Buffer::BodyAngVel, out.bodies.angvel);
  if (s) s = read_all(sim, motes::Buffer::BodyInvInertia, out.bodies.inv_inertia);
  if (s) s = read_all(sim, motes::Buffer::BodyFirst, out.bodies.first);
  if (s) s = read_all(sim, motes::Buffer::ContactLaws, out.laws);
  if (s) s = read_all(sim, motes::Buffer::Planes, out.planes);
  if (s) s = read_all(sim, motes::Buffer::Constraints, out.constraints);
  if (s) s = read_all(sim, motes::Buffer::Clusters, out.clusters);
  if (s) s = read_all(sim, motes::Buffer::ClusterMembers, out.members);
  if (s) s = read_all(sim, motes::Buffer::ClusterFrames, out.frames);
  out.particles.never_touch = mesh_never_touch(out.particles.body, out.constraints);
  out.colour_first = sim.constraint_colours();
  out.iterations = sim.settings().constraint_iterations;
  out.particles.rigid = sim.sizes().rigid_particles;
  out.params = sim.step_params();
  out.substeps = sim.settings().substeps;
  out.absorb = sim.sizes().absorb != 0;
  return s;
}

}  // namespace motes_conf
