#version 450
// particles_update: the rigid particles' [0, Nr) positions and velocities follow their body's
// pose; a neighbour-list rebuild is asked for when one has moved too far since the last build
// (one store per workgroup at most). With MOTES_FLAG_ABSORB each first hands what the constraints
// did to it to its body (shared/body_math.h: particle_handed_impulse, and its moment).
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/body_math.h"
#include "shared/neighbours.h"

shared uint group_moved;

void main() {
  uint i = thread_index();
  if (gl_LocalInvocationID.x == 0u) group_moved = 0u;
  barrier();
  if (i < p.rigid_particle_count) {
    uint b = particle_body[i];
    vec4 local = particle_local[i];
    vec4 q = body_quat[b];
    if ((p.flags & MOTES_FLAG_ABSORB) != 0u) {
      vec3 j = particle_handed_impulse(particle_vel[i], q, body_vel[b], body_angvel[b], local,
                                       particle_force[i], p.flags);
      particle_force[i] = vec4(j, 0.0f);
      particle_moment[i] = vec4(cross(quat_rotate(q, xyz(local)), j), 0.0f);
    }
    vec4 pos = vec4(particle_position(body_pos[b], q, local), particle_pos[i].w);
    particle_pos[i] = pos;
    particle_vel[i] = vec4(particle_velocity(q, body_vel[b], body_angvel[b], local),
                           particle_vel[i].w);
    if (neighbour_moved_too_far(pos, neighbour_ref_pos[i], p.neighbour_skin)) {
      atomicOr(group_moved, 1u);
    }
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u && group_moved != 0u) {
    neighbour_state[MOTES_NEIGHBOUR_REBUILD] = 1u;
  }
}
