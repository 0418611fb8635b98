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

namespace {

/// What particles_update reads and writes; impulse, moment: with MOTES_FLAG_ABSORB; points: with
/// impulse contacts.
struct Follow {
  const vec4* ref;
  const uint* body;
  const vec4* local;
  const vec4* body_pos;
  const vec4* quat;
  const vec4* body_vel;
  const vec4* angvel;
  vec4* pos;
  vec4* vel;
  vec4* impulse;
  vec4* moment;
  vec4* points;
  uint flags;
  float skin;
};

/// Particles [begin, end) follow their bodies; nonzero when one moved far enough to ask for new
/// lists. A loop of its own for each case, the buffers as restrict pointers: as a lambda called
/// per particle it reloaded every pointer from its closure around each particle's stores (the
/// small impulse chain: 171 instructions a particle, 19% of the step).
template <bool kAbsorb, bool kPoints>
uint follow_range(const Follow& f, std::int64_t begin, std::int64_t end) {
  const vec4* __restrict ref = f.ref;
  const uint* __restrict body = f.body;
  const vec4* __restrict local = f.local;
  const vec4* __restrict body_pos = f.body_pos;
  const vec4* __restrict quat = f.quat;
  const vec4* __restrict body_vel = f.body_vel;
  const vec4* __restrict angvel = f.angvel;
  vec4* __restrict pos = f.pos;
  vec4* __restrict vel = f.vel;
  vec4* __restrict impulse = f.impulse;
  vec4* __restrict moment = f.moment;
  vec4* __restrict points = f.points;
  const uint flags = f.flags;
  const float skin = f.skin;
  uint moved = 0;
  for (std::int64_t i = begin; i < end; ++i) {
    const uint b = body[i];
    // Read into locals first: the compiler then rotates local[i] once for the position and the
    // velocity (the same rotation, the same bits), which it may not across the stores.
    const vec4 q = quat[b];
    const vec4 r = local[i];
    const vec4 v = body_vel[b];
    const vec4 w = angvel[b];
    if constexpr (kAbsorb) {
      const shared::vec3 j = shared::particle_handed_impulse(vel[i], q, v, w, r, impulse[i], flags);
      impulse[i] = vec4(j, 0.0f);
      moment[i] = vec4(shared::cross(shared::quat_rotate(q, shared::xyz(r)), j), 0.0f);
    }
    const shared::vec3 x = shared::particle_position(body_pos[b], q, r);
    const shared::vec3 u = shared::particle_velocity(q, v, w, r);
    const vec4 x4(x, pos[i].w);
    if constexpr (kPoints) points[i] = shared::contact_particle(pos[i], q, r, 0u);
    pos[i] = x4;
    vel[i] = vec4(u, vel[i].w);
    moved |= shared::neighbour_moved_too_far(x4, ref[i], skin) ? 1u : 0u;
  }
  return moved;
}

template <bool kAbsorb>
uint follow_range(const Follow& f, std::int64_t begin, std::int64_t end) {
  return f.points != nullptr ? follow_range<kAbsorb, true>(f, begin, end)
                             : follow_range<kAbsorb, false>(f, begin, end);
}

uint follow_range(const Follow& f, std::int64_t begin, std::int64_t end) {
  return f.impulse != nullptr ? follow_range<true>(f, begin, end)
                              : follow_range<false>(f, begin, end);
}

}  // namespace

void OpenMPDevice::particles_update(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  impulse_contacts_ready_ = false;  // positions move: impulses_sweep lists its contacts again
  const auto n = static_cast<std::int64_t>(p.rigid_particle_count);
  const bool absorb = (p.flags & MOTES_FLAG_ABSORB) != 0u;
  Follow f{};
  f.ref = buf<vec4>(Buffer::NeighbourRefPos);
  f.body = buf<uint>(Buffer::ParticleBody);
  f.local = buf<vec4>(Buffer::ParticleLocal);
  f.body_pos = buf<vec4>(Buffer::BodyPos);
  f.quat = buf<vec4>(Buffer::BodyQuat);
  f.body_vel = buf<vec4>(Buffer::BodyVel);
  f.angvel = buf<vec4>(Buffer::BodyAngVel);
  f.pos = buf<vec4>(Buffer::ParticlePos);
  f.vel = buf<vec4>(Buffer::ParticleVel);
  f.impulse = absorb ? buf<vec4>(Buffer::ParticleForce) : nullptr;
  f.moment = absorb ? buf<vec4>(Buffer::ParticleMoment) : nullptr;
  f.flags = p.flags;
  f.skin = p.neighbour_skin;
  // Impulse contacts: each particle's rotated offset too (shared::contact_particle), the rotation
  // the position makes anyway.
  if (sizes_.impulse != 0) {
    impulse_points_.resize(std::size_t(n));
    f.points = impulse_points_.data();
  }
  uint moved = 0;
  if (!parallel(n)) {  // without entering an OpenMP region (for_items)
    moved = follow_range(f, 0, n);
  } else {
    // One run of particles a thread.
    const std::int64_t runs = team_;
#pragma omp parallel for num_threads(team_) schedule(static) reduction(| : moved)
    for (std::int64_t t = 0; t < runs; ++t)
      moved |= follow_range(f, t * n / runs, (t + 1) * n / runs);
  }
  if (moved != 0) buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] = 1;
  impulse_points_ready_ = f.points != nullptr;
  record(Kernel::ParticlesUpdate, start);
}

}  // namespace motes::openmp
