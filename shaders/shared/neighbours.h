// Neighbour (Verlet) lists with a skin, written once for every backend (docs/architecture.md,
// "Neighbour lists"). A list holds every particle of another body closer than r_i + r_j + s when it
// was built (max(r_i + r_j, h) + s for a pair with a fluid particle, h its support); while no
// particle has moved more than s/2 since, every pair in contact is in it. The decisions here are
// integers that must be identical on every backend, so their products are rounded on their own
// (mul_rn): no fused multiply-add may move a pair across the cutoff.
#ifndef MOTES_SHARED_NEIGHBOURS_H
#define MOTES_SHARED_NEIGHBOURS_H

#include "common.h"

MOTES_SHARED_BEGIN

/// NeighbourState words (a uint[4] buffer).
#define MOTES_NEIGHBOUR_REBUILD 0u        // nonzero: the next neighbours_update rebuilds
#define MOTES_NEIGHBOUR_BUILDS 1u         // builds since allocate
#define MOTES_NEIGHBOUR_OVER_CAPACITY 2u  // particles with more than K neighbours at the last build
#define MOTES_NEIGHBOUR_MAX_COUNT 3u      // the largest neighbour count at the last build

/// |a - b|^2 with every product rounded on its own, summed x, y, z in that order.
MOTES_FN float distance2_rn(vec3 a, vec3 b) {
  float dx = a.x - b.x;
  float dy = a.y - b.y;
  float dz = a.z - b.z;
  return (mul_rn(dx, dx) + mul_rn(dy, dy)) + mul_rn(dz, dz);
}

/// A fluid particle's support h in particle radii: h = 2 d = 4 r (docs/fluids.md, "Support radius
/// and the neighbour lists"). The host's FluidMaterials use the same h, which 4 r gives exactly.
#define MOTES_FLUID_SUPPORT_RADII 4.0f

/// The support h particle `index` (centre and radius in p) brings to the neighbour rule: 4 r for a
/// fluid particle (the range [fluid_first, fluid_first + fluid_count) of StepParams), else 0.
MOTES_FN float neighbour_fluid_support(vec4 p, uint index, uint fluid_first, uint fluid_count) {
  return index - fluid_first < fluid_count ? MOTES_FLUID_SUPPORT_RADII * p.w : 0.0f;
}

/// True when particle j (centre and radius in pj) belongs in the list of particle i: closer than
/// max(r_i + r_j, h) + skin, h the larger of the two particles' fluid supports
/// (neighbour_fluid_support; 0 for a pair without fluid, whose cutoff is r_i + r_j + skin as it
/// always was, bit for bit).
MOTES_FN bool neighbour_within(vec4 pi, vec4 pj, float skin, float h) {
  float cutoff = max(pi.w + pj.w, h) + skin;
  return distance2_rn(xyz(pi), xyz(pj)) < mul_rn(cutoff, cutoff);
}

/// True when a particle at `pos` has moved far enough from `ref` (its position at the last build)
/// that the lists must be rebuilt: 0.45 s, a margin below the s/2 the skin guarantees, so that
/// rounding never lets a pair come into contact unlisted.
MOTES_FN bool neighbour_moved_too_far(vec4 pos, vec4 ref, float skin) {
  float limit = 0.45f * skin;
  return distance2_rn(xyz(pos), xyz(ref)) >= mul_rn(limit, limit);
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_NEIGHBOURS_H
