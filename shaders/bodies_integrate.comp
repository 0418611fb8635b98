#version 450
// bodies_integrate: one semi-implicit Euler step of every body (shared/body_math.h); with
// MOTES_FLAG_IMPULSE_PUSH the pose moves with BodyVelPush and BodyAngMomPush (body_push_pose);
// with MOTES_FLAG_IMPULSE_SPLIT with the body's velocities, which then take the push copies
// (body_split_pose); both move the centre as the pair BodyPos + BodyPosLow.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/body_math.h"

void main() {
  uint b = thread_index();
  if (b >= p.body_count) return;
  if ((p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u) {
    vec4 pos = body_pos[b];
    vec4 low = body_pos_low[b];
    vec4 quat = body_quat[b];
    vec4 vel = body_vel[b];
    vec4 angmom = body_angmom[b];
    vec4 angvel;
    body_split_pose(pos, low, quat, vel, angmom, angvel, body_inv_inertia[b], body_vel_push[b],
                    body_angmom_push[b], p.gravity_dt);
    body_pos[b] = pos;
    body_pos_low[b] = low;
    body_quat[b] = quat;
    body_vel[b] = vel;
    body_angmom[b] = angmom;
    body_angvel[b] = angvel;
    return;
  }
  if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) {
    vec4 pos = body_pos[b];
    vec4 low = body_pos_low[b];
    vec4 quat = body_quat[b];
    vec4 angvel;
    body_push_pose(pos, low, quat, angvel, body_inv_inertia[b], body_angmom[b], body_vel_push[b],
                   body_angmom_push[b], p.gravity_dt);
    body_pos[b] = pos;
    body_pos_low[b] = low;
    body_quat[b] = quat;
    body_angvel[b] = angvel;
    return;
  }
  vec4 pos = body_pos[b];
  vec4 quat = body_quat[b];
  vec4 vel = body_vel[b];
  vec4 angmom = body_angmom[b];
  vec4 angvel;
  body_integrate(pos, quat, vel, angmom, angvel, body_inv_inertia[b], body_force[b],
                 body_torque[b], p.gravity_dt, p.flags);
  body_pos[b] = pos;
  body_quat[b] = quat;
  body_vel[b] = vel;
  body_angmom[b] = angmom;
  body_angvel[b] = angvel;
}
