#version 450
// particles_update: particle positions and velocities follow their body's pose.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/body_math.h"

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  uint b = particle_body[i];
  vec4 local = particle_local[i];
  vec4 q = body_quat[b];
  particle_pos[i] = vec4(particle_position(body_pos[b], q, local), particle_pos[i].w);
  particle_vel[i] = vec4(particle_velocity(q, body_vel[b], body_angvel[b], local), particle_vel[i].w);
}
