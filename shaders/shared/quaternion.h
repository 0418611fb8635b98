// Unit quaternions stored as vec4 (x, y, z, w): w is the scalar part.
#ifndef MOTES_SHARED_QUATERNION_H
#define MOTES_SHARED_QUATERNION_H

#include "common.h"

MOTES_SHARED_BEGIN

/// Rotates v by the unit quaternion q.
MOTES_FN vec3 quat_rotate(vec4 q, vec3 v) {
  vec3 u = vec3(q.x, q.y, q.z);
  vec3 t = cross(u, v) * 2.0f;
  return v + t * q.w + cross(u, t);
}

/// Rotates v by the inverse (conjugate) of the unit quaternion q.
MOTES_FN vec3 quat_rotate_inverse(vec4 q, vec3 v) {
  return quat_rotate(vec4(-q.x, -q.y, -q.z, q.w), v);
}

/// Hamilton product a * b (apply b, then a).
MOTES_FN vec4 quat_mul(vec4 a, vec4 b) {
  return vec4(
      a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
      a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z);
}

MOTES_FN vec4 quat_normalize(vec4 q) {
  float n = sqrt(dot(q, q));
  return q * (1.0f / n);
}

/// Orientation after turning at world angular velocity w for dt: exp(w dt / 2) * q, exactly.
MOTES_FN vec4 quat_integrate(vec4 q, vec3 w, float dt) {
  float speed = length(w);
  float half_angle = 0.5f * speed * dt;
  vec4 dq = vec4(0.0f, 0.0f, 0.0f, 1.0f);
  if (half_angle > 1.0e-12f) {
    vec3 axis = w / speed;
    float s = sin(half_angle);
    dq = vec4(axis.x * s, axis.y * s, axis.z * s, cos(half_angle));
  }
  return quat_normalize(quat_mul(dq, q));
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_QUATERNION_H
