#version 450
// contacts_compute: every dynamic particle (one thread per particle id) sums the forces of the
// particles in its neighbour list, in list order, then the planes, and writes only its own force:
// no atomics, a fixed summation order. A particle with more neighbours than its list holds walks
// the grid of the last build from the cell of its position then: the same pairs in the same order.
// With MOTES_FLAG_POSITION the terms are the shifts of position contacts and their number
// (shared/particle_shift.h). As backends/openmp/contacts_compute.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/contact_force.h"
#include "shared/grid_hash.h"
#include "grid_walk.glsl"
#include "link_exclusions.glsl"

// Position contacts (MOTES_FLAG_POSITION): the shift particle i asks of itself for its contact
// with particle j (shared/particle_shift.h), or for a rigid body's particle the reaction of its
// contact with another kind's particle; both particles' contacts within reach for mass splitting.
vec4 shift_term(uint i, uint j, vec3 xi, vec3 ui, float wi, float ri, float ni, vec4 pj, vec4 vj) {
  float nj = particle_shift_count(neighbour_count[j], p.plane_count);
  if (i < p.rigid_particle_count) {
    return rigid_contact_reaction(
        xi, ui, ri, ni, xyz(pj), xyz(vj), pj.w, vj.w, nj,
        contact_laws[particle_material[j] * p.material_count + particle_material[i]],
        p.gravity_dt.w);
  }
  return particle_contact_shift(
      xi, ui, ri, wi, ni, xyz(pj), xyz(vj), pj.w,
      shift_partner_inverse_mass(j, p.rigid_particle_count, vj.w), nj,
      contact_laws[particle_material[i] * p.material_count + particle_material[j]],
      p.gravity_dt.w);
}

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
  vec4 f = vec4(0.0f);
  bool by_impulse = impulse_particle(p.flags, i, p.rigid_particle_count);
  uint c = neighbour_count[i];
  // Position contacts: both particles' contacts within reach (mass splitting); read only then.
  bool shifts = (p.flags & MOTES_FLAG_POSITION) != 0u;
  float ni = shifts ? particle_shift_count(c, p.plane_count) : 0.0f;
  if (c <= p.neighbour_capacity) {
    for (uint k = 0u; k < c; ++k) {
      uint j = neighbour_list[k * p.particle_count + i];
      if (by_impulse && j < p.rigid_particle_count) continue;
      vec4 pj = particle_pos[j];
      vec4 vj = particle_vel[j];
      f += shifts ? shift_term(i, j, xi, ui, vi.w, pi.w, ni, pj, vj)
                  : vec4(particle_contact_force(xi, ui, pi.w, vi.w, xyz(pj), xyz(vj), pj.w, vj.w,
                                                contact_laws[law_base + particle_material[j]],
                                                p.flags),
                         0.0f);
    }
  } else {
    uint body_i = particle_body[i];
    uint lo[27];
    uint hi[27];
    int ranges = grid_walk(neighbour_ref_pos[i], lo, hi);
    for (int r = 0; r < ranges; ++r) {
      for (uint t = lo[r]; t < hi[r]; ++t) {
        uint j = grid_order[t];
        if (contact_skipped(body_i, sorted_body[t], i, j)) continue;
        if (by_impulse && j < p.rigid_particle_count) continue;
        vec4 pj = particle_pos[j];
        vec4 vj = particle_vel[j];
        f += shifts ? shift_term(i, j, xi, ui, vi.w, pi.w, ni, pj, vj)
                    : vec4(particle_contact_force(xi, ui, pi.w, vi.w, xyz(pj), xyz(vj), pj.w, vj.w,
                                                contact_laws[law_base + particle_material[j]],
                                                p.flags),
                         0.0f);
      }
    }
  }
  for (uint k = 0u; k < (by_impulse ? 0u : p.plane_count); ++k) {
    PlaneData pl = planes[k];
    f += plane_contact_term(xi, ui, pi.w, vi.w, ni, pl.normal_offset,
                            contact_laws[law_base + pl.material], p.flags, p.gravity_dt.w);
  }
  particle_force[i] = f;
}
