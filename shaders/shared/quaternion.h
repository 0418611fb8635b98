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

/// sin and cos of a half-angle. A step turns bodies by small angles (1e-4 rad is typical), where
/// GPU sin is only good to an absolute error (Vulkan allows 2^-11, NVIDIA gives about 2^-21: a
/// relative error of 1% at 1e-4 rad). Below 0.25 rad a Taylor series is used instead, accurate
/// to float precision and computed the same way on every backend.
MOTES_FN vec4 quat_sin_cos(float h) {
  if (h < 0.25f) {
    float h2 = h * h;
    return vec4(h * (1.0f - h2 * (1.0f / 6.0f) * (1.0f - h2 * (1.0f / 20.0f))),
                1.0f - h2 * 0.5f * (1.0f - h2 * (1.0f / 12.0f)), 0.0f, 0.0f);
  }
  return vec4(sin(h), cos(h), 0.0f, 0.0f);
}

/// Orientation after turning at world angular velocity w for dt: exp(w dt / 2) * q, exactly.
MOTES_FN vec4 quat_integrate(vec4 q, vec3 w, float dt) {
  float speed = length(w);
  float half_angle = 0.5f * speed * dt;
  vec4 dq = vec4(0.0f, 0.0f, 0.0f, 1.0f);
  if (half_angle > 1.0e-12f) {
    vec3 axis = w / speed;
    vec4 sc = quat_sin_cos(half_angle);
    dq = vec4(axis.x * sc.x, axis.y * sc.x, axis.z * sc.x, sc.y);
  }
  return quat_normalize(quat_mul(dq, q));
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_QUATERNION_H
