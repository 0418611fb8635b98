#version 450
// bodies_reduce: force and torque of each body (one thread per body), summed over its particles in
// particle order, as backends/openmp/bodies_reduce.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/body_math.h"

void main() {
  uint b = thread_index();
  if (b >= p.body_count) return;
  vec4 com = body_pos[b];
  vec3 f = vec3(0.0f);
  vec3 tau = vec3(0.0f);
  if (com.w != 0.0f) {
    uint end = body_first[b + 1u];
    for (uint i = body_first[b]; i < end; ++i) {
      vec4 fi = particle_force[i];
      f += xyz(fi);
      tau += particle_torque(particle_pos[i], com, fi);
    }
  }
  body_force[b] = vec4(f, 0.0f);
  body_torque[b] = vec4(tau, 0.0f);
}
