#version 450
// energy_reduce: the energy guard's reduction (shared/energy.h). One workgroup of 256 invocations
// per block of 256 items (the flat 2D-dispatch index beyond 65,535 groups): each invocation its
// item's energy into shared memory, then the tree of shared/energy.h (slot t += slot t + s,
// s = 128, ..., 1, a barrier between levels), and invocation 0 writes the block's four words. No
// atomics: the same sums in the same order on every run and on every backend.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY
#include "kernel_common.glsl"
#include "shared/energy.h"

#if WORKGROUP_SIZE != 256
#error "energy_reduce: one invocation per item of a block of MOTES_ENERGY_BLOCK (256)"
#endif

shared float kinetic[MOTES_ENERGY_BLOCK];
shared float potential[MOTES_ENERGY_BLOCK];
shared float largest[MOTES_ENERGY_BLOCK];
shared uint item[MOTES_ENERGY_BLOCK];

void main() {
  uint t = gl_LocalInvocationID.x;
  uint bodies = p.body_count;
  uint items = energy_items(bodies, p.particle_count, p.rigid_particle_count);
  // The padding groups of a 2D dispatch have no block: the whole workgroup leaves at once.
  if (flat_group() >= energy_blocks(items)) return;
  uint j = thread_index();
  vec3 ref = vec3(bits_float(energy_partials[0]), bits_float(energy_partials[1]),
                  bits_float(energy_partials[2]));
  vec3 e = vec3(0.0f);
  if (j < bodies) {
    e = item_energy(body_pos[j], body_vel[j], body_pos[j].w, true, body_angvel[j], body_angmom[j],
                    p.gravity_dt, ref);
  } else if (j < items) {
    uint i = p.rigid_particle_count + (j - bodies);
    e = item_energy(particle_pos[i], particle_vel[i], particle_vel[i].w, false, vec4(0.0f),
                    vec4(0.0f), p.gravity_dt, ref);
  }
  bool counts = e.z != 0.0f;
  kinetic[t] = e.x;
  potential[t] = e.y;
  largest[t] = counts ? e.x : MOTES_ENERGY_NO_KINETIC;
  item[t] = counts ? j : MOTES_ENERGY_NONE;
  barrier();
  for (uint s = MOTES_ENERGY_BLOCK / 2u; s > 0u; s >>= 1u) {
    if (t < s) {
      precise float k = kinetic[t] + kinetic[t + s];
      precise float u = potential[t] + potential[t + s];
      kinetic[t] = k;
      potential[t] = u;
      if (energy_larger(largest[t + s], item[t + s], largest[t], item[t])) {
        largest[t] = largest[t + s];
        item[t] = item[t + s];
      }
    }
    barrier();
  }
  if (t == 0u) {
    uint block = MOTES_ENERGY_HEADER + MOTES_ENERGY_WORDS * flat_group();
    energy_partials[block + MOTES_ENERGY_KINETIC] = float_bits(kinetic[0]);
    energy_partials[block + MOTES_ENERGY_POTENTIAL] = float_bits(potential[0]);
    energy_partials[block + MOTES_ENERGY_MAX_KINETIC] = float_bits(largest[0]);
    energy_partials[block + MOTES_ENERGY_MAX_ITEM] = item[0];
  }
}
