// Rigid-body integration and particle-from-body update (Harada, GPU Gems 3 ch. 29).
// Body frame = principal axes, so the body-frame inverse inertia is diagonal.
#ifndef MOTES_SHARED_BODY_MATH_H
#define MOTES_SHARED_BODY_MATH_H

#include "common.h"
#include "params.h"
#include "quaternion.h"

MOTES_SHARED_BEGIN

/// World angular velocity w = R diag(inv_inertia) R^T L.
MOTES_FN vec3 body_angular_velocity(vec4 q, vec4 inv_inertia, vec3 angular_momentum) {
  vec3 lb = quat_rotate_inverse(q, angular_momentum);
  return quat_rotate(q, vec3(lb.x * inv_inertia.x, lb.y * inv_inertia.y, lb.z * inv_inertia.z));
}

/// One semi-implicit Euler step of a dynamic body (pos_invm.w > 0):
///   v += dt (F/m + g);  x += dt v;  L += dt tau;
///   q_half = exp(w(q, L) dt / 4) q;  q = exp(w(q_half, L) dt / 2) q;  w = w(q, L).
/// flags (StepParams.flags) may ask for one half: MOTES_FLAG_BODY_VELOCITY stops after v and L
/// (w from the unchanged q), MOTES_FLAG_BODY_POSE starts from v and L as they are (the impulse
/// stage runs between the two). Static bodies (pos_invm.w == 0) are left untouched.
MOTES_FN void body_integrate(MOTES_INOUT(vec4) pos_invm, MOTES_INOUT(vec4) quat,
                             MOTES_INOUT(vec4) vel, MOTES_INOUT(vec4) angmom,
                             MOTES_OUT(vec4) angvel, vec4 inv_inertia, vec4 force, vec4 torque,
                             vec4 gravity_dt, uint flags) {
  float inv_m = pos_invm.w;
  if (inv_m == 0.0f) {
    angvel = vec4(0.0f);
    return;
  }
  float dt = gravity_dt.w;
  vec3 v = xyz(vel);
  vec3 l = xyz(angmom);
  if ((flags & MOTES_FLAG_POSITION) != 0u) {  // position contacts: predict with gravity alone
    v = v + xyz(gravity_dt) * dt;
  } else if ((flags & MOTES_FLAG_BODY_POSE) == 0u) {
    v = v + (xyz(force) * inv_m + xyz(gravity_dt)) * dt;
    l = l + xyz(torque) * dt;
  }
  if ((flags & MOTES_FLAG_BODY_VELOCITY) != 0u) {
    vel = vec4(v, 0.0f);
    angmom = vec4(l, 0.0f);
    angvel = vec4(body_angular_velocity(quat, inv_inertia, l), 0.0f);
    return;
  }
  vec3 x = xyz(pos_invm) + v * dt;
  vec4 q = quat;
  vec3 w = vec3(0.0f);
  if (l.x != 0.0f || l.y != 0.0f || l.z != 0.0f) {  // a body at rest in rotation stays so
    // Midpoint rule: turn by w taken at the half-step orientation. Taking w at the start instead
    // adds rotational energy every step (first order), which makes tumbling bodies drift.
    vec4 q_half = quat_integrate(quat, body_angular_velocity(quat, inv_inertia, l), 0.5f * dt);
    q = quat_integrate(quat, body_angular_velocity(q_half, inv_inertia, l), dt);
    w = body_angular_velocity(q, inv_inertia, l);
  }
  pos_invm = vec4(x, inv_m);
  quat = q;
  vel = vec4(v, 0.0f);
  angmom = vec4(l, 0.0f);
  angvel = vec4(w, 0.0f);
}

/// The pose half of body_integrate (MOTES_FLAG_BODY_POSE) moved with other velocities than the
/// body's own: with MOTES_FLAG_IMPULSE_PUSH the impulse stage moves a body with the velocities its
/// sweeps with position correction left (vel_push, angmom_push) and keeps the relaxed ones
/// (shared/impulse.h); w then comes from the body's own angular momentum at the new orientation.
/// The centre moves as a pair of floats, pos_invm and low (BodyPosLow): the move and what earlier
/// moves' rounding lost are added to it and what this addition's rounding loses is kept in low
/// (compensated summation), so that moves smaller than the spacing of floats at the centre add up
/// instead of vanishing. 50 m from the origin floats are 3.8 um apart, and a resting body's moves
/// are far smaller: its centre stuck while it turned, and chains and piles there jittered
/// (docs/architecture.md, "Impulse contacts").
MOTES_FN void body_push_pose(MOTES_INOUT(vec4) pos_invm, MOTES_INOUT(vec4) low,
                             MOTES_INOUT(vec4) quat, MOTES_OUT(vec4) angvel, vec4 inv_inertia,
                             vec4 angmom, vec4 vel_push, vec4 angmom_push, vec4 gravity_dt) {
  vec4 v = vel_push;
  vec4 l = angmom_push;
  vec4 w = vec4(0.0f);
  vec3 start = xyz(pos_invm);
  body_integrate(pos_invm, quat, v, l, w, inv_inertia, vec4(0.0f), vec4(0.0f), gravity_dt,
                 MOTES_FLAG_BODY_POSE);
  if (pos_invm.w == 0.0f) {
    angvel = vec4(0.0f);
    return;
  }
  // The move's products rounded on their own (mul_rn), so that every backend keeps the same low.
  float dt = gravity_dt.w;
  vec3 move = vec3(mul_rn(vel_push.x, dt), mul_rn(vel_push.y, dt), mul_rn(vel_push.z, dt));
  vec3 lost;
  vec3 x = add_exact(start, move + xyz(low), lost);
  pos_invm = vec4(x, pos_invm.w);
  low = vec4(lost, 0.0f);
  angvel = vec4(body_angular_velocity(quat, inv_inertia, xyz(angmom)), 0.0f);
}

/// Split impulses' pose (MOTES_FLAG_BODY_POSE | MOTES_FLAG_IMPULSE_SPLIT): the body moves with
/// the velocities it has (those the correcting sweeps left) and then keeps vel_push and
/// angmom_push (those the relaxing sweeps left, which never saw the position correction).
MOTES_FN void body_split_pose(MOTES_INOUT(vec4) pos_invm, MOTES_INOUT(vec4) low,
                              MOTES_INOUT(vec4) quat, MOTES_INOUT(vec4) vel,
                              MOTES_INOUT(vec4) angmom, MOTES_OUT(vec4) angvel, vec4 inv_inertia,
                              vec4 vel_push, vec4 angmom_push, vec4 gravity_dt) {
  vec4 v = vel;
  vec4 l = angmom;
  vel = vel_push;
  angmom = angmom_push;
  body_push_pose(pos_invm, low, quat, angvel, inv_inertia, angmom, v, l, gravity_dt);
}

/// One semi-implicit Euler step of a free particle (a one-particle body that does not spin), the
/// linear half of body_integrate with the same arithmetic: v += dt (F/m + g); x += dt v.
/// Static particles (vel.w, the inverse mass, == 0) are left untouched.
/// With MOTES_FLAG_POSITION the force is not used (position contacts: gravity predicts).
MOTES_FN void particle_integrate(MOTES_INOUT(vec4) pos, MOTES_INOUT(vec4) vel, vec4 force,
                                 vec4 gravity_dt, uint flags) {
  float inv_m = vel.w;
  if (inv_m == 0.0f) {
    return;
  }
  float dt = gravity_dt.w;
  vec3 f = (flags & MOTES_FLAG_POSITION) != 0u ? vec3(0.0f) : xyz(force);
  vec3 v = xyz(vel) + (f * inv_m + xyz(gravity_dt)) * dt;
  vec3 x = xyz(pos) + v * dt;
  pos = vec4(x, pos.w);
  vel = vec4(v, inv_m);
}

/// Torque about the centre of mass of a force applied at a particle centre.
MOTES_FN vec3 particle_torque(vec4 particle_pos, vec4 body_pos, vec4 force) {
  return cross(xyz(particle_pos) - xyz(body_pos), xyz(force));
}

/// World position of a body's particle (local: body-frame offset from the centre of mass).
MOTES_FN vec3 particle_position(vec4 body_pos, vec4 quat, vec4 local) {
  return xyz(body_pos) + quat_rotate(quat, xyz(local));
}

/// World velocity of a body's particle: v + w x (R r).
MOTES_FN vec3 particle_velocity(vec4 quat, vec4 body_vel, vec4 angvel, vec4 local) {
  vec3 r = quat_rotate(quat, xyz(local));
  return xyz(body_vel) + cross(xyz(angvel), r);
}

/// What the constraints did to a rigid particle, as an impulse for its body: m (v - v_point), with
/// v its velocity now (changed by constraint_apply, as a cloth or rope attached to it pulled) and
/// v_point its body's velocity at it (particle_velocity); w = 1 / m of the particle (0: static,
/// no impulse). The other end of each constraint got the opposite momentum, so the body taking
/// this keeps the total momentum.
MOTES_FN vec3 particle_absorbed_impulse(vec4 vel, vec4 quat, vec4 body_vel, vec4 angvel,
                                        vec4 local) {
  if (vel.w == 0.0f) {
    return vec3(0.0f);
  }
  return (xyz(vel) - particle_velocity(quat, body_vel, angvel, local)) / vel.w;
}

/// particles_update with MOTES_FLAG_ABSORB: the impulse a rigid particle hands its body: what the
/// constraints did to it (particle_absorbed_impulse), or with MOTES_FLAG_PARTICLE_SHIFT the
/// reaction of its position contacts with other kinds' particles that contacts_compute summed
/// into ParticleForce (shared/particle_shift.h: rigid_contact_reaction).
MOTES_FN vec3 particle_handed_impulse(vec4 vel, vec4 quat, vec4 body_vel, vec4 angvel, vec4 local,
                                      vec4 force, uint flags) {
  if ((flags & MOTES_FLAG_PARTICLE_SHIFT) != 0u) {
    return xyz(force);
  }
  return particle_absorbed_impulse(vel, quat, body_vel, angvel, local);
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_BODY_MATH_H
