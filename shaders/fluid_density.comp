#version 450
// fluid_density: one thread per fluid particle; its density and lambda, a gather over its
// neighbour list in list order (over capacity: the 27 cells of the last build, whose extra
// particles beyond h add zeros), then the planes in order (shared/fluid.h). Each thread writes
// only its own FluidState entry. As backends/openmp/fluid_density.cpp.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY
#include "kernel_common.glsl"
#include "shared/fluid.h"
#include "shared/grid_hash.h"
#include "grid_walk.glsl"
#include "link_exclusions.glsl"

// Particle j's terms of fluid particle i's density (w of `sums`: rho; `gathered`: grad_i C_i and
// the denominator).
void add_neighbour(uint j, vec3 xi, FluidMaterial f, inout float rho, inout vec4 gathered) {
  vec3 rij = xi - xyz(particle_pos[j]);
  bool fluid_j = fluid_particle(j, p.fluid_first, p.fluid_count);
  float mj = fluid_neighbour_mass(fluid_j, fluid_materials[particle_material[j]].density_h.z,
                                  particle_pos[j].w, f);
  rho += mj * fluid_poly6(dot(rij, rij), f.density_h.y);
  gathered += fluid_gradient_term(rij, mj, fluid_j ? particle_vel[j].w : 0.0f, f.density_h.x,
                                  f.density_h.y);
}

void main() {
  uint k = thread_index();
  if (k >= p.fluid_count) return;
  uint i = p.fluid_first + k;
  vec3 xi = xyz(particle_pos[i]);
  FluidMaterial f = fluid_materials[particle_material[i]];
  float rho = f.density_h.z * fluid_poly6(0.0f, f.density_h.y);
  vec4 gathered = vec4(0.0f);
  uint c = neighbour_count[i];
  if (c <= p.neighbour_capacity) {
    for (uint s = 0u; s < c; ++s) {
      add_neighbour(list_entry(s, i), xi, f, rho, gathered);
    }
  } else {
    uint body_i = particle_body[i];
    GridWalk walk = grid_walk_begin(neighbour_ref_pos[i]);
    uint lo, hi;
    while (grid_walk_next(walk, lo, hi)) {
      for (uint t = lo; t < hi; ++t) {
        uint j = grid_order[t];
        if (!contact_skipped(body_i, sorted_body[t], i, j)) add_neighbour(j, xi, f, rho, gathered);
      }
    }
  }
  for (uint s = 0u; s < p.plane_count; ++s) {
    vec4 wall = fluid_plane_density(planes[s].normal_offset, xi, f);
    rho += wall.w;
    gathered += vec4(xyz(wall), 0.0f);
  }
  float lambda = fluid_lambda(fluid_constraint(rho, f.density_h.x, true), gathered,
                              particle_vel[i].w, f.density_h.w);
  bool first = (p.flags & MOTES_FLAG_POSITION_FIRST) != 0u;
  fluid_state[k] = vec4(rho, lambda, first ? lambda : fluid_state[k].z + lambda, 0.0f);
}
