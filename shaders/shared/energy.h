// energy_reduce, the energy guard's reduction (docs/reliability.md, "Guards while running"),
// written once for every backend: the mechanical energy (kinetic + gravitational potential) of
// every item that carries mass, and the layout of the EnergyPartials buffer its blocks write.
//
// Items: the rigid bodies [0, B) (StepParams.body_count), then the particles that are not a rigid
// body's [Nr, N) (free spheres, soft-body, cloth and rope particles): item j < B is body j, item
// j >= B is particle Nr + (j - B). An item counts only when its inverse mass (BodyPos.w,
// ParticleVel.w) is > 0 and everything it is computed from is finite: static bodies and pinned
// particles count nothing, and so does a body or particle that is not finite (particles_check
// names that one; its energy would be meaningless).
//
// Every block of MOTES_ENERGY_BLOCK consecutive items writes four words: the sum of its items'
// kinetic and potential energies, added as a tree in a fixed order (slot t += slot t + s for
// s = BLOCK / 2, ..., 1: the same order on every backend, whatever order threads run in), the
// largest single item's kinetic energy and that item (the lowest index among equal ones). No
// float atomics: the host reads the blocks and adds them in double.
#ifndef MOTES_SHARED_ENERGY_H
#define MOTES_SHARED_ENERGY_H

#include "common.h"
#include "motion_check.h"

MOTES_SHARED_BEGIN

/// Items per block: one workgroup (Vulkan) or thread block (CUDA) of 256 threads, one item each.
#define MOTES_ENERGY_BLOCK 256u
/// EnergyPartials (uint words): words [0, 3) are the float bits of the reference point x_ref (xyz)
/// that potential energy is measured from, written by the host (the kernel only reads them; word
/// 3 is 0); block k's words start at MOTES_ENERGY_HEADER + MOTES_ENERGY_WORDS k.
#define MOTES_ENERGY_HEADER 4u
#define MOTES_ENERGY_WORDS 4u
#define MOTES_ENERGY_KINETIC 0u      // float bits of the block's summed kinetic energy (J)
#define MOTES_ENERGY_POTENTIAL 1u    // float bits of its summed potential energy (J), from x_ref
#define MOTES_ENERGY_MAX_KINETIC 2u  // float bits of its largest item kinetic energy (-1: none)
#define MOTES_ENERGY_MAX_ITEM 3u     // that item (MOTES_ENERGY_NONE: the block counts no item)
#define MOTES_ENERGY_NONE 0xFFFFFFFFu
/// What an empty slot of the tree holds as its largest kinetic energy: below any item's.
#define MOTES_ENERGY_NO_KINETIC -1.0f

/// Items of a simulation: its rigid bodies and its particles that are not a rigid body's.
MOTES_FN uint energy_items(uint body_count, uint particle_count, uint rigid_particle_count) {
  return body_count + (particle_count - rigid_particle_count);
}

/// Blocks of MOTES_ENERGY_BLOCK items (the last may be partial).
MOTES_FN uint energy_blocks(uint items) {
  return items / MOTES_ENERGY_BLOCK + (items % MOTES_ENERGY_BLOCK != 0u ? 1u : 0u);
}

#ifdef __cplusplus
MOTES_FN float bits_float(uint u) {
#ifdef __CUDA_ARCH__
  return __uint_as_float(u);
#else
  float f = 0.0f;
  std::memcpy(&f, &u, sizeof f);
  return f;
#endif
}
#else
float bits_float(uint u) { return uintBitsToFloat(u); }
#endif

/// True when x, y and z are finite.
MOTES_FN bool finite3(vec4 v) { return finite_bits(v.x) && finite_bits(v.y) && finite_bits(v.z); }

/// The energy of one item: x = kinetic, y = potential (J), z = 1 when it counts (else all 0).
/// Kinetic: 0.5 |v|^2 / w (+ 0.5 omega . L for a rigid body: `spin` true); potential:
/// -(g . (x - x_ref)) / w. Every product is rounded on its own (mul_rn) and the sums run in a
/// fixed order, so every backend computes the same terms (a division may differ by an ulp on
/// Vulkan).
MOTES_FN vec3 item_energy(vec4 pos, vec4 vel, float inverse_mass, bool spin, vec4 angvel,
                          vec4 angmom, vec4 gravity, vec3 ref) {
  if (!(inverse_mass > 0.0f) || !finite_bits(inverse_mass) || !finite3(pos) || !finite3(vel) ||
      (spin && !(finite3(angvel) && finite3(angmom)))) {
    return vec3(0.0f);
  }
  float kinetic = 0.5f * (motion_speed2(vel) / inverse_mass);
  if (spin) {
    float wl =
        (mul_rn(angvel.x, angmom.x) + mul_rn(angvel.y, angmom.y)) + mul_rn(angvel.z, angmom.z);
    kinetic = kinetic + 0.5f * wl;
  }
  float gh = (mul_rn(gravity.x, pos.x - ref.x) + mul_rn(gravity.y, pos.y - ref.y)) +
             mul_rn(gravity.z, pos.z - ref.z);
  return vec3(kinetic, -(gh / inverse_mass), 1.0f);
}

/// True when (kinetic b, item jb) beats (kinetic a, item ja) as the block's largest: more kinetic
/// energy, or as much from a lower item. A total order, so the winner does not depend on the
/// order of the comparisons.
MOTES_FN bool energy_larger(float b, uint jb, float a, uint ja) {
  return b > a || (b == a && jb < ja);
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_ENERGY_H
