// A rigid body as its contacts see it (impulse contacts, shared/impulse.h, and position contacts,
// shared/position.h): its centre, inverse mass and world inverse inertia, its velocities, the
// inverse mass a contact meets along a direction (with mass splitting), and where the contact of
// two particles or of a particle and a plane acts.
#ifndef MOTES_SHARED_CONTACT_BODY_H
#define MOTES_SHARED_CONTACT_BODY_H

#include "body_math.h"
#include "common.h"
#include "params.h"

MOTES_SHARED_BEGIN

/// What a contact needs to know of one of its bodies. A plane or a static body has com.w == 0 and
/// inv_inertia == 0, and so takes no part in the contact's effective mass.
struct ImpulseBody {
  vec4 com;       // xyz: centre of mass, w: inverse mass
  vec4 inv_diag;  // world inverse inertia I^-1 = R diag(inverse moments) R^T: xx, yy, zz
  vec4 inv_off;   // its off-diagonal terms: xy, xz, yz
  vec4 vel;       // linear velocity now (this iteration)
  vec4 angvel;    // angular velocity now
  vec4 vel0;      // xyz: linear velocity at the start of the impulse stage, w: its contacts
  vec4 angvel0;   // angular velocity at the start of the impulse stage
};

/// The part of a body as contacts see it that a substep's sweeps do not change: its centre and
/// inverse mass, and its inverse inertia turned to the world once (a contact applies it four
/// times). Velocities zero: impulse_body_state fills them.
MOTES_FN ImpulseBody impulse_body_frame(vec4 com, vec4 quat, vec4 inv_inertia) {
  ImpulseBody b;
  b.com = com;
  // Columns of R: the body axes in the world; I^-1 = sum over k of inv_k c_k c_k^T.
  vec3 c0 = quat_rotate(quat, vec3(1.0f, 0.0f, 0.0f));
  vec3 c1 = quat_rotate(quat, vec3(0.0f, 1.0f, 0.0f));
  vec3 c2 = quat_rotate(quat, vec3(0.0f, 0.0f, 1.0f));
  vec3 a0 = c0 * inv_inertia.x;
  vec3 a1 = c1 * inv_inertia.y;
  vec3 a2 = c2 * inv_inertia.z;
  b.inv_diag =
      vec4(a0.x * c0.x + a1.x * c1.x + a2.x * c2.x, a0.y * c0.y + a1.y * c1.y + a2.y * c2.y,
           a0.z * c0.z + a1.z * c1.z + a2.z * c2.z, 0.0f);
  b.inv_off = vec4(a0.x * c0.y + a1.x * c1.y + a2.x * c2.y, a0.x * c0.z + a1.x * c1.z + a2.x * c2.z,
                   a0.y * c0.z + a1.y * c1.z + a2.y * c2.z, 0.0f);
  b.vel = vec4(0.0f);
  b.angvel = vec4(0.0f);
  b.vel0 = vec4(0.0f);
  b.angvel0 = vec4(0.0f);
  return b;
}

/// A body's velocities now and at the substep's start into b; in the counting pass
/// (MOTES_FLAG_IMPULSE_COUNT) the substep starts now, so its start is its present state.
MOTES_FN void impulse_body_state(MOTES_INOUT(ImpulseBody) b, vec4 vel, vec4 angvel, vec4 vel0,
                                 vec4 angvel0, uint flags) {
  b.vel = vel;
  b.angvel = angvel;
  b.vel0 = vel0;
  b.angvel0 = angvel0;
  if ((flags & MOTES_FLAG_IMPULSE_COUNT) != 0u) {
    b.vel0 = vec4(xyz(vel), 1.0f);
    b.angvel0 = angvel;
  }
}

/// What a counting pass keeps of a body as the substep's start (impulses_apply with
/// MOTES_FLAG_IMPULSE_COUNT): its velocity now (xyz) and its contact count (w). Position contacts
/// count again before each projection sweep but keep the velocity of the first
/// (MOTES_FLAG_POSITION_FIRST), which the velocity pass's targets start from.
MOTES_FN vec4 impulse_start_velocity(vec4 now, vec4 kept, float count, uint flags) {
  bool keep = (flags & MOTES_FLAG_POSITION) != 0u && (flags & MOTES_FLAG_POSITION_FIRST) == 0u;
  return vec4(keep ? xyz(kept) : xyz(now), count);
}

/// The angular part of impulse_start_velocity.
MOTES_FN vec4 impulse_start_angular_velocity(vec4 now, vec4 kept, uint flags) {
  bool keep = (flags & MOTES_FLAG_POSITION) != 0u && (flags & MOTES_FLAG_POSITION_FIRST) == 0u;
  return keep ? kept : now;
}

/// A body as the contacts of an impulse sweep see it, from its buffers' values.
MOTES_FN ImpulseBody impulse_body_of(vec4 com, vec4 quat, vec4 inv_inertia, vec4 vel, vec4 angvel,
                                     vec4 vel0, vec4 angvel0, uint flags) {
  ImpulseBody b = impulse_body_frame(com, quat, inv_inertia);
  impulse_body_state(b, vel, angvel, vel0, angvel0, flags);
  return b;
}

/// The body's world inverse inertia applied to v: I^-1 v.
MOTES_FN vec3 impulse_inverse_inertia(MOTES_IN(ImpulseBody) b, vec3 v) {
  return vec3(b.inv_diag.x * v.x + b.inv_off.x * v.y + b.inv_off.y * v.z,
              b.inv_off.x * v.x + b.inv_diag.y * v.y + b.inv_off.z * v.z,
              b.inv_off.y * v.x + b.inv_off.z * v.y + b.inv_diag.z * v.z);
}

/// A body that takes no part: a plane.
MOTES_FN ImpulseBody impulse_wall() {
  ImpulseBody w;
  w.com = vec4(0.0f);
  w.inv_diag = vec4(0.0f);
  w.inv_off = vec4(0.0f);
  w.vel = vec4(0.0f);
  w.angvel = vec4(0.0f);
  w.vel0 = vec4(0.0f);
  w.angvel0 = vec4(0.0f);
  return w;
}

/// 1/m + (r x d) . I^-1 (r x d): the inverse mass a unit impulse along d at arm r meets, times
/// the body's contact count (mass splitting). 0 for a wall or a static body.
MOTES_FN float impulse_inverse_mass(MOTES_IN(ImpulseBody) b, vec3 r, vec3 d) {
  if (b.com.w == 0.0f) {
    return 0.0f;  // a wall or a static body (inverse inertia 0 too): what the terms would give
  }
  vec3 rd = cross(r, d);
  float k = b.com.w + dot(rd, impulse_inverse_inertia(b, rd));
  return max(b.vel0.w, 1.0f) * k;
}

/// The change of the velocity of a body's material point at arm r that a unit impulse along d
/// makes, as a contact sees it (times the body's contact count: mass splitting):
/// n (d / m + (I^-1 (r x d)) x r). Its dot product with d is impulse_inverse_mass. 0 for a wall.
MOTES_FN vec3 impulse_response(MOTES_IN(ImpulseBody) b, vec3 r, vec3 d) {
  if (b.com.w == 0.0f) {
    return vec3(0.0f);
  }
  vec3 w = impulse_inverse_inertia(b, cross(r, d));
  return (d * b.com.w + cross(w, r)) * max(b.vel0.w, 1.0f);
}

/// Velocity of a body's material point at arm r: v + w x r.
MOTES_FN vec3 impulse_point_velocity(vec4 vel, vec4 angvel, vec3 r) {
  return xyz(vel) + cross(xyz(angvel), r);
}

/// Where the impulse of two particles acts: their midpoint.
MOTES_FN vec3 pair_contact_point(vec4 xa, vec4 xb) { return (xyz(xa) + xyz(xb)) * 0.5f; }

/// Where the impulse of a particle and a plane acts: the particle's point nearest the plane.
MOTES_FN vec3 plane_contact_point(vec4 xa, vec4 normal_offset) {
  return xyz(xa) - xyz(normal_offset) * xa.w;
}

/// Where a contact at point c acts on the body of particle xi: at c for impulse contacts; at xi's
/// centre for position contacts, whose friction holds the particles' centres (shared/position.h:
/// contact_position). Both lie on the contact normal through xi, so the normal part of the impulse
/// turns the body alike.
MOTES_FN vec3 contact_acting_point(vec3 c, vec4 xi, uint flags) {
  return (flags & MOTES_FLAG_POSITION) != 0u ? xyz(xi) : c;
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_CONTACT_BODY_H
