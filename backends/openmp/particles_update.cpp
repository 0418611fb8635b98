// particles_update: the rigid particles' positions and velocities follow their body's pose; a
// neighbour-list rebuild is asked for when one has moved too far since the last build. With
// MOTES_FLAG_ABSORB each first hands what the constraints did to it to its body (an impulse and its
// moment, shared/body_math.h: particle_absorbed_impulse); with MOTES_FLAG_PARTICLE_SHIFT too, the
// reaction of its position contacts that contacts_compute left in ParticleForce.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/body_math.h"
#include "shared/impulse.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::particles_update(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  impulse_contacts_ready_ = false;  // positions move: impulses_sweep lists its contacts again
  const auto n = static_cast<std::int64_t>(p.rigid_particle_count);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  const uint* body = buf<uint>(Buffer::ParticleBody);
  const vec4* local = buf<vec4>(Buffer::ParticleLocal);
  const vec4* body_pos = buf<vec4>(Buffer::BodyPos);
  const vec4* quat = buf<vec4>(Buffer::BodyQuat);
  const vec4* body_vel = buf<vec4>(Buffer::BodyVel);
  const vec4* angvel = buf<vec4>(Buffer::BodyAngVel);
  vec4* pos = buf<vec4>(Buffer::ParticlePos);
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  const bool absorb = (p.flags & MOTES_FLAG_ABSORB) != 0u;
  vec4* impulse = absorb ? buf<vec4>(Buffer::ParticleForce) : nullptr;
  vec4* moment = absorb ? buf<vec4>(Buffer::ParticleMoment) : nullptr;
  // Impulse contacts: each particle's rotated offset too (shared::contact_particle), the rotation
  // the position makes anyway.
  vec4* points = nullptr;
  if (sizes_.impulse != 0) {
    impulse_points_.resize(std::size_t(n));
    points = impulse_points_.data();
  }

  // One particle follows its body; true when it moved far enough to ask for new lists.
  const auto follow = [&](std::int64_t i) {
    const uint b = body[i];
    // Read into locals first: the compiler then rotates local[i] once for the position and the
    // velocity (the same rotation, the same bits), which it may not across the stores.
    const vec4 q = quat[b];
    const vec4 r = local[i];
    const vec4 v = body_vel[b];
    const vec4 w = angvel[b];
    if (absorb) {
      const shared::vec3 j =
          shared::particle_handed_impulse(vel[i], q, v, w, r, impulse[i], p.flags);
      impulse[i] = vec4(j, 0.0f);
      moment[i] = vec4(shared::cross(shared::quat_rotate(q, shared::xyz(r)), j), 0.0f);
    }
    const shared::vec3 x = shared::particle_position(body_pos[b], q, r);
    const shared::vec3 u = shared::particle_velocity(q, v, w, r);
    if (points != nullptr) points[i] = shared::contact_particle(pos[i], q, r, 0u);
    pos[i] = vec4(x, pos[i].w);
    vel[i] = vec4(u, vel[i].w);
    return shared::neighbour_moved_too_far(pos[i], ref[i], p.neighbour_skin);
  };
  uint moved = 0;
  if (!parallel(n)) {  // without entering an OpenMP region (for_items)
    for (std::int64_t i = 0; i < n; ++i) moved |= follow(i) ? 1u : 0u;
  } else {
#pragma omp parallel for num_threads(team_) schedule(static) reduction(| : moved)
    for (std::int64_t i = 0; i < n; ++i) moved |= follow(i) ? 1u : 0u;
  }
  if (moved != 0) buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] = 1;
  impulse_points_ready_ = points != nullptr;
  record(Kernel::ParticlesUpdate, start);
}

}  // namespace motes::openmp
