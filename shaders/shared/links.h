// Cloth and ropes (Jakobsen 2001, "Advanced character physics"), written once for every backend
// (docs/architecture.md, "Cloth and ropes"). Their particles are integrated like free spheres
// (particle_integrate: semi-implicit Euler, which is position Verlet with v = (x - x_prev) / dt),
// damped by StepParams.linked_damping, then distance constraints are relaxed colour by colour
// (constraints_solve). A constraint moves its two particles along the link, in proportion to
// their inverse masses (a pinned particle has inverse mass 0), and changes their velocities by the
// same displacement / dt, so that velocity stays (x - x_prev) / dt.
#ifndef MOTES_SHARED_LINKS_H
#define MOTES_SHARED_LINKS_H

#include "common.h"

MOTES_SHARED_BEGIN

/// One distance constraint between particles a and b (device particle ids).
struct Constraint {
  uint a;
  uint b;
  float rest;       // rest length (m)
  float stiffness;  // fraction of the error removed per projection, in (0, 1]
};

/// ParticleBody of a cloth or rope particle: this bit, a clear MESH bit, then the object (10
/// bits) and the particle's place (u, v) on the object's lattice (10 bits each; a rope has v = 0).
/// Particles of one object within two lattice steps in u and in v are excluded from contact with
/// each other: they are linked, or two links apart.
/// A cloth made from a triangle mesh has no lattice: its particles' words are LINKED | MESH | the
/// object | the vertex (20 bits), and the particles within two links of each one are listed in
/// the LinkExclusions buffer (contact_listed, contact_skipped).
#define MOTES_LINKED_BIT 0x80000000u
#define MOTES_LINKED_MESH_BIT 0x40000000u
#define MOTES_LINKED_MAX_OBJECTS 1024u
#define MOTES_LINKED_MAX_SIDE 1024u
#define MOTES_LINKED_MAX_MESH_POINTS 0x100000u

MOTES_FN uint linked_body(uint object, uint u, uint v) {
  return MOTES_LINKED_BIT | (object << 20) | (u << 10) | v;
}

MOTES_FN uint linked_mesh_body(uint object, uint vertex) {
  return MOTES_LINKED_BIT | MOTES_LINKED_MESH_BIT | (object << 20) | vertex;
}

/// |a - b| <= 2 for lattice coordinates a, b.
MOTES_FN bool lattice_near(uint a, uint b) { return (a > b ? a - b : b - a) <= 2u; }

/// True when particles with these ParticleBody words never touch: the same rigid body (or the
/// same particle), or two particles of one lattice cloth or rope within two lattice steps. Two
/// particles of one mesh cloth are not decided here (contact_listed).
MOTES_FN bool contact_excluded(uint body_i, uint body_j) {
  if (body_i == body_j) {
    return true;
  }
  if ((body_i & body_j & MOTES_LINKED_BIT) == 0u || (body_i >> 20) != (body_j >> 20) ||
      (body_i & MOTES_LINKED_MESH_BIT) != 0u) {
    return false;
  }
  return lattice_near((body_i >> 10) & 1023u, (body_j >> 10) & 1023u) &&
         lattice_near(body_i & 1023u, body_j & 1023u);
}

/// True for two particles of one mesh cloth: they touch unless the second is in the first's
/// LinkExclusions list. That buffer holds, for the linked particles [Nl, N), N - Nl + 1 starts
/// (counted from the lists' beginning, right after them), then each particle's list of the
/// particle ids within two links of it, ascending.
MOTES_FN bool contact_listed(uint body_i, uint body_j) {
  return (body_i & MOTES_LINKED_MESH_BIT) != 0u && (body_i >> 20) == (body_j >> 20);
}

#ifdef __cplusplus
/// contact_excluded, then for two particles i and j of one mesh cloth whether j is in i's
/// LinkExclusions list `exclusions` (C++ and CUDA; shaders/link_exclusions.glsl is the same in
/// GLSL). Used wherever contacts are found: neighbours_build and contacts_compute's grid walk.
MOTES_FN bool contact_skipped(uint body_i, uint body_j, uint i, uint j, const uint* exclusions,
                              uint particle_count, uint linked_first) {
  if (contact_excluded(body_i, body_j)) {
    return true;
  }
  if (!contact_listed(body_i, body_j)) {
    return false;
  }
  const uint lists = particle_count - linked_first + 1u;
  const uint end = exclusions[i - linked_first + 1u];
  for (uint e = exclusions[i - linked_first]; e < end; ++e) {
    const uint k = exclusions[lists + e];
    if (k >= j) {
      return k == j;
    }
  }
  return false;
}
#endif

/// Velocity of particle i before particle_integrate: Jakobsen's damping (the velocity times
/// 1 - damping per substep) for the linked particles [linked_first, N), unchanged for the others.
MOTES_FN vec4 linked_damped(vec4 vel, uint i, uint linked_first, float damping) {
  if (i < linked_first) {
    return vel;
  }
  return vec4(xyz(vel) * (1.0f - damping), vel.w);
}

/// The displacement d of a constraint's first particle per unit inverse mass: a moves by wa * d,
/// b by -wb * d. Zero when both are pinned or the particles coincide (no direction).
MOTES_FN vec3 constraint_correction(vec4 pa, vec4 pb, float wa, float wb, float rest,
                                    float stiffness) {
  vec3 delta = xyz(pb) - xyz(pa);
  float len = sqrt(dot(delta, delta));
  float w = wa + wb;
  if (w == 0.0f || len == 0.0f) {
    return vec3(0.0f);
  }
  return delta * (stiffness * (len - rest) / (len * w));
}

/// Moves a particle by `shift` and changes its velocity by shift / dt.
MOTES_FN void constraint_apply(MOTES_INOUT(vec4) pos, MOTES_INOUT(vec4) vel, vec3 shift,
                               float inv_dt) {
  pos = vec4(xyz(pos) + shift, pos.w);
  vel = vec4(xyz(vel) + shift * inv_dt, vel.w);
}

/// One projection of constraint c: constraint_correction, then each particle moved by it in
/// proportion to its inverse mass (the velocity's w) with constraint_apply. What constraints_solve
/// and constraints_relax do to each constraint, on every backend.
MOTES_FN void constraint_project(MOTES_INOUT(vec4) xa, MOTES_INOUT(vec4) xb, MOTES_INOUT(vec4) va,
                                 MOTES_INOUT(vec4) vb, Constraint c, float inv_dt) {
  vec3 d = constraint_correction(xa, xb, va.w, vb.w, c.rest, c.stiffness);
  constraint_apply(xa, va, d * va.w, inv_dt);
  constraint_apply(xb, vb, d * -vb.w, inv_dt);
}

MOTES_SHARED_END

#ifdef __cplusplus
static_assert(sizeof(motes::shared::Constraint) == 16, "Constraint layout");
#endif

#endif  // MOTES_SHARED_LINKS_H
