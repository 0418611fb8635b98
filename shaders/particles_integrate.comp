#version 450
// particles_integrate: semi-implicit Euler on the free spheres [Nr, N) (shared/body_math.h), or with
// MOTES_FLAG_PARTICLE_SHIFT the mean of their contacts' shifts (shared/particle_shift.h), and
// a neighbour-list rebuild asked for when one has moved too far since the last build (one store
// per workgroup at most).
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/body_math.h"
#include "shared/neighbours.h"
#include "shared/particle_shift.h"

shared uint group_moved;

void main() {
  uint i = p.rigid_particle_count + thread_index();
  if (gl_LocalInvocationID.x == 0u) group_moved = 0u;
  barrier();
  if (i < p.particle_count) {
    vec4 pos = particle_pos[i];
    vec4 vel = particle_vel[i];
    if ((p.flags & MOTES_FLAG_PARTICLE_SHIFT) != 0u) {
      particle_shift_apply(pos, vel, particle_force[i], p.gravity_dt.w);
    } else {
      vel = linked_damped(vel, i, p.linked_first, p.linked_damping);
      particle_integrate(pos, vel, particle_force[i], p.gravity_dt, p.flags);
    }
    particle_pos[i] = pos;
    particle_vel[i] = vel;
    if (neighbour_moved_too_far(pos, neighbour_ref_pos[i], p.neighbour_skin)) {
      atomicOr(group_moved, 1u);
    }
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u && group_moved != 0u) {
    neighbour_state[MOTES_NEIGHBOUR_REBUILD] = 1u;
  }
}
