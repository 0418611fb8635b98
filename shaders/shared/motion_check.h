// particles_check, the run-time motion guard (docs/reliability.md, "Guards while running"),
// written once for every backend: per particle the squared rate (|v| / d)^2, in particle diameters
// per second, and whether its position and velocity are finite. The device reduces these to four
// words (a uint[4] buffer, MotionCheck), in passes: a reset, the largest rate and the first
// non-finite particle, the first particle with that rate, then its speed. Every word is an integer
// decided by max or min, so the result does not depend on the order threads arrive in.
#ifndef MOTES_SHARED_MOTION_CHECK_H
#define MOTES_SHARED_MOTION_CHECK_H

#include "common.h"

#if defined(__cplusplus) && !defined(__CUDA_ARCH__)
#include <cstring>
#endif

MOTES_SHARED_BEGIN

/// MotionCheck words.
#define MOTES_MOTION_RATE2 0u    // float bits of the largest (|v| / d)^2 of a finite particle
#define MOTES_MOTION_FASTEST 1u  // the smallest particle index with that rate (NONE: no particle)
#define MOTES_MOTION_NON_FINITE 2u  // the smallest index of a particle with a NaN or infinity
#define MOTES_MOTION_SPEED2 3u      // float bits of |v|^2 of particle FASTEST
#define MOTES_MOTION_WORDS 4u
#define MOTES_MOTION_NONE 0xFFFFFFFFu
/// The passes of particles_check (the pass argument of each dispatch).
#define MOTES_MOTION_PASS_RESET 0u    // one thread: RATE2 = SPEED2 = 0, the indices NONE
#define MOTES_MOTION_PASS_REDUCE 1u   // every particle: max of its rate bits, min of non-finite i
#define MOTES_MOTION_PASS_FASTEST 2u  // every particle whose rate bits equal RATE2: min of i
#define MOTES_MOTION_PASS_SPEED 3u    // one thread: SPEED2 of particle FASTEST
/// The bits of the largest finite float: a rate too large for a float saturates here.
#define MOTES_MOTION_SATURATED 0x7F7FFFFFu

#ifdef __cplusplus
MOTES_FN uint float_bits(float f) {
#ifdef __CUDA_ARCH__
  return __float_as_uint(f);
#else
  uint u = 0;
  std::memcpy(&u, &f, sizeof u);
  return u;
#endif
}
#else
uint float_bits(float f) { return floatBitsToUint(f); }
#endif

/// False for a NaN or an infinity.
MOTES_FN bool finite_bits(float f) { return (float_bits(f) & 0x7F800000u) != 0x7F800000u; }

/// True when the particle's position and velocity (xyz) are all finite.
MOTES_FN bool motion_finite(vec4 pos, vec4 vel) {
  return finite_bits(pos.x) && finite_bits(pos.y) && finite_bits(pos.z) && finite_bits(vel.x) &&
         finite_bits(vel.y) && finite_bits(vel.z);
}

/// |v|^2, every product rounded on its own (the same bits on every backend).
MOTES_FN float motion_speed2(vec4 vel) {
  return (mul_rn(vel.x, vel.x) + mul_rn(vel.y, vel.y)) + mul_rn(vel.z, vel.z);
}

/// The bits of (|v| / d)^2 for a finite particle (d = 2 x the radius in pos.w): positive floats
/// order as their bits do. A rate beyond the float range (|v|^2 overflowing, or d = 0 with v not
/// 0) saturates at MOTES_MOTION_SATURATED; 0 for a particle at rest.
MOTES_FN uint motion_rate2_bits(vec4 pos, vec4 vel) {
  float s2 = motion_speed2(vel);
  float d = pos.w + pos.w;
  float d2 = mul_rn(d, d);
  if (!(s2 > 0.0f)) return 0u;
  if (!(d2 > 0.0f) || !finite_bits(s2)) return MOTES_MOTION_SATURATED;
  float r2 = s2 / d2;
  return finite_bits(r2) ? float_bits(r2) : MOTES_MOTION_SATURATED;
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_MOTION_CHECK_H
