#version 450
// impulses_apply: each dynamic body (one thread per body) sums its particles' impulses, counts and
// moments in particle order and applies them (shared/impulse.h: body_apply_impulse); with
// MOTES_FLAG_IMPULSE_COUNT it first keeps its velocities and contact count as the start of the
// impulse stage; with MOTES_FLAG_IMPULSE_PUSH it keeps the velocities it leaves in BodyVelPush and
// BodyAngMomPush. As backends/openmp/impulses_apply.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/neighbours.h"

void main() {
  uint b = thread_index();
  if (b >= p.body_count) return;
  vec4 com = body_pos[b];
  vec4 sum = vec4(0.0f);
  vec3 m = vec3(0.0f);
  if (com.w != 0.0f) {
    uint end = body_first[b + 1u];
    for (uint i = body_first[b]; i < end; ++i) {
      sum = sum + particle_force[i];
      m += xyz(particle_moment[i]);
    }
  }
  if ((p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u) {
    body_vel_start[b] = impulse_start_velocity(body_vel[b], body_vel_start[b], sum.w, p.flags);
    body_angvel_start[b] =
        impulse_start_angular_velocity(body_angvel[b], body_angvel_start[b], p.flags);
    // The counting pass has read every slot: the body's particles' slots are now this build's.
    if (com.w != 0.0f) {
      uint builds = neighbour_state[MOTES_NEIGHBOUR_BUILDS];
      uint end = body_first[b + 1u];
      for (uint i = body_first[b]; i < end; ++i) impulse_stamp[i] = builds;
    }
  }
  vec4 vel = body_vel[b];
  vec4 angmom = body_angmom[b];
  vec4 angvel;
  vec4 quat = body_quat[b];
  body_apply_contacts(com, quat, body_inv_inertia[b], vel, angmom, angvel, xyz(sum), m,
                      p.gravity_dt, p.flags);
  body_pos[b] = com;
  body_quat[b] = quat;
  body_vel[b] = vel;
  body_angmom[b] = angmom;
  body_angvel[b] = angvel;
  if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) {
    body_vel_push[b] = vel;
    body_angmom_push[b] = angmom;
  }
}
