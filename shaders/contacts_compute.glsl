// The body of contacts_compute.comp (the force law) and contacts_compute_shift.comp (position
// contacts, MOTES_FLAG_POSITION), chosen at compile time by MOTES_CONTACT_SHIFTS (0 or 1), so that
// the force law's shader carries none of the shifts' code or registers (as the two instances of
// backends/cuda/contacts_compute.cu's kernel; issue 27 measured the shared shader's branch at
// 1 us a step of W2 on an H200). Every dynamic particle (one thread per particle id) sums the
// terms of the particles in its neighbour list, in list order, then the planes, and writes only
// its own: no atomics, a fixed summation order. A particle with more neighbours than its list
// holds walks the grid of the last build from the cell of its position then: the same pairs in the
// same order. As backends/openmp/contacts_compute.cpp and contacts_shift.cpp.
#define MOTES_STATE_READONLY  // writes particle_force only
#include "kernel_common.glsl"
#include "shared/contact_force.h"
#include "shared/grid_hash.h"
#include "grid_walk.glsl"
#include "link_exclusions.glsl"

#if MOTES_CONTACT_SHIFTS
// A term: the shift (xyz) and whether the contact counts (w).
#define Term vec4
vec4 stored(vec4 f) { return f; }

// Position contacts: the shift particle i asks of itself for its contact with particle j
// (shared/particle_shift.h), or for a rigid body's particle the reaction of its contact with
// another kind's particle; both particles' contacts within reach (ni, nj) for mass splitting.
vec4 contact_term(uint i, uint j, vec3 xi, vec3 ui, float ri, float wi, float ni, uint law_base) {
  if (shift_pair_skipped(i, j, p.fluid_first, p.fluid_count)) return vec4(0.0f);
  vec4 pj = particle_pos[j];
  vec4 vj = particle_vel[j];
  float nj = particle_shift_count(neighbour_count[j], p.plane_count);
  if (i < p.rigid_particle_count) {
    return rigid_contact_reaction(
        xi, ui, ri, ni, xyz(pj), xyz(vj), pj.w, vj.w, nj,
        contact_laws[particle_material[j] * p.material_count + particle_material[i]],
        p.gravity_dt.w);
  }
  return particle_contact_shift(xi, ui, ri, wi, ni, xyz(pj), xyz(vj), pj.w,
                                shift_partner_inverse_mass(j, p.rigid_particle_count, vj.w), nj,
                                contact_laws[law_base + particle_material[j]], p.gravity_dt.w);
}

vec4 plane_term(vec3 xi, vec3 ui, float ri, float wi, float ni, PlaneData pl, uint law_base) {
  return plane_contact_shift(xi, ui, ri, ni, pl.normal_offset, contact_laws[law_base + pl.material],
                             p.gravity_dt.w);
}
#else
// A term: a force, summed in three components (a fourth would cost an addition a contact).
#define Term vec3
vec4 stored(vec3 f) { return vec4(f, 0.0f); }

// The force law: the force of particle j on i (zero unless they overlap).
vec3 contact_term(uint i, uint j, vec3 xi, vec3 ui, float ri, float wi, float ni, uint law_base) {
  vec4 pj = particle_pos[j];
  vec4 vj = particle_vel[j];
  return particle_contact_force(xi, ui, ri, wi, xyz(pj), xyz(vj), pj.w, vj.w,
                                contact_laws[law_base + particle_material[j]], p.flags);
}

vec3 plane_term(vec3 xi, vec3 ui, float ri, float wi, float ni, PlaneData pl, uint law_base) {
  return plane_contact_force(xi, ui, ri, wi, pl.normal_offset,
                             contact_laws[law_base + pl.material], p.flags);
}
#endif

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  vec4 pi = particle_pos[i];
  vec4 vi = particle_vel[i];
  if (vi.w == 0.0f) {  // static particle: its force is never used
    particle_force[i] = vec4(0.0f);
    return;
  }
  vec3 xi = xyz(pi);
  vec3 ui = xyz(vi);
  uint law_base = particle_material[i] * p.material_count;
  Term f = Term(0.0f);
  bool by_impulse = impulse_particle(p.flags, i, p.rigid_particle_count);
  uint c = neighbour_count[i];
#if MOTES_CONTACT_SHIFTS
  float ni = particle_shift_count(c, p.plane_count);
#else
  float ni = 0.0f;
#endif
  if (c <= p.neighbour_capacity) {
    for (uint k = 0u; k < c; ++k) {
      uint j = list_entry(k, i);
      if (by_impulse && j < p.rigid_particle_count) continue;
      f += contact_term(i, j, xi, ui, pi.w, vi.w, ni, law_base);
    }
  } else {
    uint body_i = particle_body[i];
    GridWalk walk = grid_walk_begin(neighbour_ref_pos[i]);
    uint lo, hi;
    while (grid_walk_next(walk, lo, hi)) {
      for (uint t = lo; t < hi; ++t) {
        uint j = grid_order[t];
        if (contact_skipped(body_i, sorted_body[t], i, j)) continue;
        if (by_impulse && j < p.rigid_particle_count) continue;
        f += contact_term(i, j, xi, ui, pi.w, vi.w, ni, law_base);
      }
    }
  }
  for (uint k = 0u; k < (by_impulse ? 0u : p.plane_count); ++k) {
    f += plane_term(xi, ui, pi.w, vi.w, ni, planes[k], law_base);
  }
  particle_force[i] = stored(f);
}
