// Per-contact force of the DEM model (Harada, GPU Gems 3 ch. 29, with LAMMPS gran/hooke's
// mass-proportional damping): linear spring + normal dashpot + viscous tangential force with an
// optional Coulomb cap. One definition for every backend.
#ifndef MOTES_SHARED_CONTACT_FORCE_H
#define MOTES_SHARED_CONTACT_FORCE_H

#include "common.h"
#include "params.h"
#include "particle_shift.h"

MOTES_SHARED_BEGIN

/// True when particle i (< particle count) is a rigid body's and the scene resolves rigid contacts
/// by impulses (MOTES_FLAG_IMPULSE): its contacts with rigid particles and planes then get no
/// force here (impulses_compute has them).
MOTES_FN bool impulse_particle(uint flags, uint i, uint rigid_count) {
  return (flags & MOTES_FLAG_IMPULSE) != 0u && i < rigid_count;
}

/// Force on particle i from a contact with unit normal n (pointing from i towards the other
/// body), overlap > 0, relative velocity vrel = v_other - v_i and effective mass meff.
MOTES_FN vec3 contact_law_force(vec3 n, float overlap, vec3 vrel, float meff, ContactLaw law,
                                uint flags) {
  float vn = dot(vrel, n);
  // Repulsive magnitude: spring plus dashpot on the overlap rate (-vn).
  float fn = law.stiffness * overlap - law.damping * meff * vn;
  if ((flags & MOTES_FLAG_CLAMP_ATTRACTION) != 0u) {
    fn = max(fn, 0.0f);
  }
  vec3 vt = vrel - n * vn;
  vec3 ft = vt * (law.tangential * meff);
  if (law.friction >= 0.0f) {
    float cap = law.friction * abs(fn);
    float ft2 = dot(ft, ft);
    if (ft2 > cap * cap) {
      ft = ft * (cap / sqrt(ft2));
    }
  }
  return ft - n * fn;
}

/// Force on particle i (centre xi, velocity vi, radius ri, inverse mass inv_mi) from particle j.
/// Zero when they do not overlap or their centres coincide. inv_mi + inv_mj must be > 0.
MOTES_FN vec3 particle_contact_force(vec3 xi, vec3 vi, float ri, float inv_mi, vec3 xj, vec3 vj,
                                     float rj, float inv_mj, ContactLaw law, uint flags) {
  vec3 d = xj - xi;
  float dist2 = dot(d, d);
  float rsum = ri + rj;
  if (dist2 >= rsum * rsum || dist2 == 0.0f) {
    return vec3(0.0f);
  }
  float dist = sqrt(dist2);
  vec3 n = d / dist;
  float meff = 1.0f / (inv_mi + inv_mj);
  return contact_law_force(n, rsum - dist, vj - vi, meff, law, flags);
}

/// Force on particle i from a static half-space plane (the wall has infinite mass).
MOTES_FN vec3 plane_contact_force(vec3 xi, vec3 vi, float ri, float inv_mi, vec4 normal_offset,
                                  ContactLaw law, uint flags) {
  vec3 np = xyz(normal_offset);
  float gap = dot(np, xi) - normal_offset.w;
  float overlap = ri - gap;
  if (overlap <= 0.0f) {
    return vec3(0.0f);
  }
  return contact_law_force(-np, overlap, -vi, 1.0f / inv_mi, law, flags);
}

/// contacts_compute's term for particle i's contact with a static plane: the force (w = 0), or
/// with MOTES_FLAG_POSITION the shift it asks and 1 when they overlap (shared/particle_shift.h; h:
/// the substep; ni: i's contacts within reach, particle_shift_count). A particle's contact with
/// another particle takes particle_contact_force, or particle_contact_shift with the partner's
/// inverse mass from shift_partner_inverse_mass, or rigid_contact_reaction (the backends choose).
MOTES_FN vec4 plane_contact_term(vec3 xi, vec3 vi, float ri, float inv_mi, float ni,
                                 vec4 normal_offset, ContactLaw law, uint flags, float h) {
  if ((flags & MOTES_FLAG_POSITION) != 0u) {
    return plane_contact_shift(xi, vi, ri, ni, normal_offset, law, h);
  }
  return vec4(plane_contact_force(xi, vi, ri, inv_mi, normal_offset, law, flags), 0.0f);
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_CONTACT_FORCE_H
