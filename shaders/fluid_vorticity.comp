#version 450
// fluid_vorticity: one thread per fluid particle; its vorticity omega_i and surface normal n_i, a
// gather over its fluid neighbours in list order (solids skipped; over capacity: the 27 cells of
// the last build, whose extra particles beyond h add zeros), and a copy of its velocity for the
// velocity pass (shared/fluid.h). Each thread writes only its own entries. As
// backends/openmp/fluid_vorticity.cpp.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY
#include "kernel_common.glsl"
#include "shared/fluid.h"
#include "shared/grid_hash.h"
#include "grid_walk.glsl"
#include "link_exclusions.glsl"

// Particle j's terms of fluid particle i's vorticity and normal (none for a solid j).
void add_neighbour(uint j, vec3 xi, vec3 vi, float h, inout vec3 omega, inout vec3 ni) {
  if (!fluid_particle(j, p.fluid_first, p.fluid_count)) return;
  vec3 grad = fluid_spiky_gradient(xi - xyz(particle_pos[j]), h);
  float mj = fluid_materials[particle_material[j]].density_h.z;
  float rhoj = fluid_state[j - p.fluid_first].x;
  omega += fluid_vorticity_term(vi, xyz(particle_vel[j]), mj, rhoj, grad);
  ni += fluid_normal_term(mj, rhoj, grad, h);
}

void main() {
  uint k = thread_index();
  if (k >= p.fluid_count) return;
  uint i = p.fluid_first + k;
  vec3 xi = xyz(particle_pos[i]);
  vec3 vi = xyz(particle_vel[i]);
  float h = fluid_materials[particle_material[i]].density_h.y;
  vec3 omega = vec3(0.0f);
  vec3 ni = vec3(0.0f);
  uint c = neighbour_count[i];
  if (c <= p.neighbour_capacity) {
    for (uint s = 0u; s < c; ++s) {
      add_neighbour(list_entry(s, i), xi, vi, h, omega, ni);
    }
  } else {
    uint body_i = particle_body[i];
    GridWalk walk = grid_walk_begin(neighbour_ref_pos[i]);
    uint lo, hi;
    while (grid_walk_next(walk, lo, hi)) {
      for (uint t = lo; t < hi; ++t) {
        uint j = grid_order[t];
        if (!contact_skipped(body_i, sorted_body[t], i, j)) add_neighbour(j, xi, vi, h, omega, ni);
      }
    }
  }
  fluid_vel_old[k] = vec4(vi, 0.0f);
  fluid_aux[k] = vec4(omega, sqrt(dot(omega, omega)));
  fluid_normal[k] = vec4(ni, 0.0f);
}
