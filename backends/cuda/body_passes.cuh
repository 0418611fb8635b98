// The per-body and per-particle work of bodies_reduce, bodies_integrate and particles_update, used
// by their kernels and by the fused bodies_step kernel, so both compute the same thing.
#pragma once

#include "body_buffers.h"
#include "shared/body_math.h"
#include "shared/neighbours.h"

namespace motes::cuda {

/// Adds particle force fi at position xi to a body's sums (the one definition of both reductions).
__device__ inline void body_reduce_add(shared::vec3& f, shared::vec3& tau, shared::vec4 xi,
                                       shared::vec4 com, shared::vec4 fi) {
  f += shared::xyz(fi);
  tau += shared::particle_torque(xi, com, fi);
}

/// Force and torque of body b, summed over its particles in particle order.
__device__ inline void body_reduce(const BodyBuffers& d, shared::uint b) {
  const shared::vec4 com = d.body_pos[b];
  shared::vec3 f(0.0f);
  shared::vec3 tau(0.0f);
  if (com.w != 0.0f) {
    const shared::uint end = d.first[b + 1];
    for (shared::uint i = d.first[b]; i < end; ++i)
      body_reduce_add(f, tau, d.pos[i], com, d.force[i]);
  }
  d.body_force[b] = shared::vec4(f, 0.0f);
  d.body_torque[b] = shared::vec4(tau, 0.0f);
}

/// One semi-implicit Euler step of body b.
__device__ inline void body_step(const BodyBuffers& d, shared::uint b, shared::vec4 gravity_dt,
                                 shared::uint flags) {
  shared::vec4 pos = d.body_pos[b];
  shared::vec4 quat = d.quat[b];
  shared::vec4 vel = d.body_vel[b];
  shared::vec4 angmom = d.angmom[b];
  shared::vec4 angvel;
  shared::body_integrate(pos, quat, vel, angmom, angvel, d.inv_inertia[b], d.body_force[b],
                         d.body_torque[b], gravity_dt, flags);
  d.body_pos[b] = pos;
  d.quat[b] = quat;
  d.body_vel[b] = vel;
  d.angmom[b] = angmom;
  d.angvel[b] = angvel;
}

/// Position and velocity of particle i from the pose of body b; true when it has moved too far
/// from its position at the last neighbour-list build.
__device__ inline bool particle_update(const BodyBuffers& d, shared::uint i, shared::uint b,
                                       float skin) {
  const shared::vec4 q = d.quat[b];
  const shared::vec4 local = d.local[i];
  const shared::vec4 x(shared::particle_position(d.body_pos[b], q, local), d.pos[i].w);
  d.pos[i] = x;
  d.vel[i] =
      shared::vec4(shared::particle_velocity(q, d.body_vel[b], d.angvel[b], local), d.vel[i].w);
  return shared::neighbour_moved_too_far(x, d.ref[i], skin);
}

/// Asks for a neighbour-list rebuild when any thread of the block saw a particle move too far
/// (one store per block at most). Every thread of the block must call it.
__device__ inline void ask_rebuild_if(const BodyBuffers& d, bool moved) {
  if (__syncthreads_or(moved) != 0 && threadIdx.x == 0) d.state[MOTES_NEIGHBOUR_REBUILD] = 1;
}

}  // namespace motes::cuda
