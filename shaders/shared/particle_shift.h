// Position contacts of cloth and rope particles (issue 27; docs/architecture.md, "Position
// contacts of particles"): Macklin, Müller, Chentanez, Kim 2014, "Unified particle physics for
// real-time applications", sections 4.2 and 6.1. A pair of particles closer than the sum of their
// radii is the constraint C = r_i + r_j - |x_i - x_j| >= 0; its correction moves i along the
// pair's normal by w_i / (n_i w_i + n_j w_j) of the overlap d, and of the pair's tangential
// displacement over the substep (x - x_start = v h: every shift also changes the velocity by
// shift / h) all of it while that stays within mu d (static friction), else mu d of it (kinetic;
// one mu for both, the materials' friction; a negative friction holds fully). n is a particle's
// contacts within reach: its list's count plus the planes. This is mass splitting (each contact
// sees a particle with n times its inverse mass; the impulse contacts do the same) in place of
// the paper's constraint averaging (a particle moved by the mean of its contacts' shifts), which
// does not keep momentum when two partners have different counts: a cloth meeting a rope lost
// 4.6% of its momentum with it. The two particles of a pair move by exactly opposite momenta.
// contacts_compute with MOTES_FLAG_POSITION sums these shifts in its fixed order (the number of
// overlapping contacts in w); particles_integrate with MOTES_FLAG_PARTICLE_SHIFT moves each
// particle by the sum: a parallel Jacobi sweep, deterministic, no atomics.
#ifndef MOTES_SHARED_PARTICLE_SHIFT_H
#define MOTES_SHARED_PARTICLE_SHIFT_H

#include "common.h"
#include "params.h"

MOTES_SHARED_BEGIN

/// The shift of a particle (share of the pair, 1 for a plane or a static partner) in contact with
/// unit normal n (from the particle towards the other), overlap d > 0, and tangential
/// displacement relative to the other over the substep dx.
MOTES_FN vec3 contact_shift(vec3 n, float overlap, vec3 dx, float share, float friction) {
  vec3 dt = dx - n * dot(dx, n);
  float len2 = dot(dt, dt);
  float cap = friction * overlap;
  // Sliding beyond the cone keeps all but mu d of its displacement (kinetic friction).
  float scale = friction >= 0.0f && len2 > cap * cap ? cap / sqrt(len2) : 1.0f;
  return (n * overlap + dt * scale) * -share;
}

/// What particle i (centre xi, velocity vi, radius ri, inverse mass wi > 0, ni contacts within
/// reach) asks of itself for its contact with particle j: (shift, 1) when they overlap, else 0.
/// h: the substep.
MOTES_FN vec4 particle_contact_shift(vec3 xi, vec3 vi, float ri, float wi, float ni, vec3 xj,
                                     vec3 vj, float rj, float wj, float nj, ContactLaw law,
                                     float h) {
  vec3 d = xj - xi;
  float dist2 = dot(d, d);
  float rsum = ri + rj;
  if (dist2 >= rsum * rsum || dist2 == 0.0f) {
    return vec4(0.0f);
  }
  float dist = sqrt(dist2);
  return vec4(
      contact_shift(d / dist, rsum - dist, (vi - vj) * h, wi / (ni * wi + nj * wj), law.friction),
      1.0f);
}

/// The same for a static half-space plane (it takes none of the shift).
MOTES_FN vec4 plane_contact_shift(vec3 xi, vec3 vi, float ri, float ni, vec4 normal_offset,
                                  ContactLaw law, float h) {
  vec3 np = xyz(normal_offset);
  float overlap = ri - (dot(np, xi) - normal_offset.w);
  if (overlap <= 0.0f) {
    return vec4(0.0f);
  }
  return vec4(contact_shift(-np, overlap, vi * h, 1.0f / ni, law.friction), 1.0f);
}

/// A rigid body's particle in a position contact with a free, soft, cloth or rope particle j:
/// the rigid particles do not move in the shift sweeps (their partners take the whole correction,
/// particle_contact_shift with the rigid side's inverse mass 0), and the body takes the reaction,
/// minus the momentum j gains: -shift / (w_j h), with the shift exactly as j computes it (law_j:
/// j's row of the pair laws), and 1 in w when they overlap. A pinned j (w_j = 0) gives none.
MOTES_FN vec4 rigid_contact_reaction(vec3 xi, vec3 vi, float ri, float ni, vec3 xj, vec3 vj,
                                     float rj, float wj, float nj, ContactLaw law_j, float h) {
  if (wj == 0.0f) {
    return vec4(0.0f);
  }
  vec4 s = particle_contact_shift(xj, vj, rj, wj, nj, xi, vi, ri, 0.0f, ni, law_j, h);
  return vec4(xyz(s) * (-1.0f / (wj * h)), s.w);
}

/// The inverse mass a partner j takes in particle_contact_shift: a rigid body's particle
/// (j < rigid_count) does not move in the shift sweeps (rigid_contact_reaction), so 0.
MOTES_FN float shift_partner_inverse_mass(uint j, uint rigid_count, float wj) {
  return j < rigid_count ? 0.0f : wj;
}

/// Two fluid particles have no position contact: the density constraint sets their spacing, and
/// a contact at d would fight its equilibrium where the liquid is compressed (docs/fluids.md, "The
/// substep", 6). Fluid against any other kind keeps it. [fluid_first, + fluid_count): StepParams'.
MOTES_FN bool shift_pair_skipped(uint i, uint j, uint fluid_first, uint fluid_count) {
  return i - fluid_first < fluid_count && j - fluid_first < fluid_count;
}

/// A particle's contacts within reach for the shares above: its list's count and the planes.
MOTES_FN float particle_shift_count(uint listed, uint planes) { return float(listed + planes); }

/// particles_integrate with MOTES_FLAG_PARTICLE_SHIFT: the shifts contacts_compute summed (xyz;
/// the number of overlapping contacts in w), the position moved by them and the velocity by them
/// / h.
MOTES_FN void particle_shift_apply(MOTES_INOUT(vec4) pos, MOTES_INOUT(vec4) vel, vec4 sum,
                                   float h) {
  if (sum.w == 0.0f || vel.w == 0.0f) {
    return;
  }
  vec3 shift = xyz(sum);
  pos = vec4(xyz(pos) + shift, pos.w);
  vel = vec4(xyz(vel) + shift / h, vel.w);
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_PARTICLE_SHIFT_H
