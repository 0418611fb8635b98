#version 450
// The largest squared particle speed of this frame, folded into the running maximum that speed
// colours scale by (render::ParticleColors::observe's rule: NaN never counts), on the zero-copy
// path. Squares are non-negative, so their float bits order as unsigned integers (atomicMax).
#extension GL_GOOGLE_include_directive : require
#define COLORS_WRITABLE
#include "colors.glsl"

layout(local_size_x = 256) in;
layout(std430, set = 0, binding = 1) readonly buffer Velocities {
  vec4 velocity[];
};
layout(push_constant) uniform Count {
  uint particles;
} count;

shared float largest[256];

void main() {
  float m = 0.0;
  uint stride = gl_NumWorkGroups.x * 256u;
  for (uint i = gl_GlobalInvocationID.x; i < count.particles; i += stride) {
    vec3 v = velocity[i].xyz;
    float v2 = v.x * v.x + v.y * v.y + v.z * v.z;
    if (v2 > m) m = v2;
  }
  uint k = gl_LocalInvocationIndex;
  largest[k] = m;
  barrier();
  for (uint half_size = 128u; half_size > 0u; half_size >>= 1) {
    if (k < half_size) largest[k] = max(largest[k], largest[k + half_size]);
    barrier();
  }
  if (k == 0u && largest[0] > 0.0) atomicMax(colors.speed2, floatBitsToUint(largest[0]));
}
