// Runs over MPI ranks (docs/scale-out.md), written once for every backend: the layout in which
// halo_pack gathers the state a neighbour rank holds copies of and halo_unpack scatters it, and
// particles_displacement's measure of how far particles have moved since the ranks last
// partitioned the scene.
#ifndef MOTES_SHARED_HALO_H
#define MOTES_SHARED_HALO_H

#include "common.h"
#include "motion_check.h"
#include "neighbours.h"

MOTES_SHARED_BEGIN

/// HaloData: particle entry k (of StepParams.halo_particles) at MOTES_HALO_PARTICLE_VEC4S k:
/// ParticlePos, then ParticleVel; after all of them, rigid body entry j at
/// MOTES_HALO_PARTICLE_VEC4S halo_particles + MOTES_HALO_BODY_VEC4S j: BodyPos, BodyQuat,
/// BodyVel, BodyAngMom, BodyAngVel. Entry k's particle is HaloIndex[halo_first + k], entry j's
/// body HaloIndex[halo_first + halo_particles + j]; an index out of range (not below
/// particle_count, or body_count) is skipped by both kernels.
#define MOTES_HALO_PARTICLE_VEC4S 2u
#define MOTES_HALO_BODY_VEC4S 5u

/// PartitionCheck words.
#define MOTES_PARTITION_DISPLACEMENT2 0u  // float bits of the largest squared displacement
#define MOTES_PARTITION_WORDS 1u
/// The passes of particles_displacement (the pass argument of each dispatch).
#define MOTES_PARTITION_PASS_RESET 0u   // one thread: DISPLACEMENT2 = 0
#define MOTES_PARTITION_PASS_REDUCE 1u  // every particle: max of displacement2_bits
/// An infinity's bits: what a particle that is not finite counts as (larger than any finite
/// squared distance, so the ranks partition at once and the motion guard names it).
#define MOTES_PARTITION_NOT_FINITE 0x7F800000u

/// The float bits of |pos - ref|^2 (xyz; every product rounded on its own, the same bits on
/// every backend), or MOTES_PARTITION_NOT_FINITE when either is not finite or the square
/// overflows. Non-negative floats order as their bits, so the largest is an integer max.
MOTES_FN uint displacement2_bits(vec4 pos, vec4 ref) {
  if (!(finite_bits(pos.x) && finite_bits(pos.y) && finite_bits(pos.z) && finite_bits(ref.x) &&
        finite_bits(ref.y) && finite_bits(ref.z))) {
    return MOTES_PARTITION_NOT_FINITE;
  }
  uint bits = float_bits(distance2_rn(xyz(pos), xyz(ref)));
  return bits > MOTES_PARTITION_NOT_FINITE ? MOTES_PARTITION_NOT_FINITE : bits;
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_HALO_H
