#version 450
// fluid_update: one thread per particle; a fluid particle's correction dx_i of the density
// constraint, a gather over its neighbour list in list order (over capacity: the 27 cells of the
// last build, whose extra particles beyond h add zeros), then the planes' slope terms, as a shift
// in ParticleForce (w = 1); every other particle's ParticleForce 0 (shared/fluid.h). As
// backends/openmp/fluid_update.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/fluid.h"
#include "shared/grid_hash.h"
#include "grid_walk.glsl"
#include "link_exclusions.glsl"

// Particle j's term of fluid particle i's correction.
vec3 shift_term(uint j, vec3 xi, float lambda_i, FluidMaterial f) {
  vec3 rij = xi - xyz(particle_pos[j]);
  bool fluid_j = fluid_particle(j, p.fluid_first, p.fluid_count);
  float mj = fluid_neighbour_mass(fluid_j, fluid_materials[particle_material[j]].density_h.z,
                                  particle_pos[j].w, f);
  float lambda_j = fluid_j ? fluid_state[j - p.fluid_first].y : 0.0f;
  float s_corr = fluid_j ? fluid_s_corr(dot(rij, rij), f.density_h.z, f) : 0.0f;
  return fluid_shift_term(lambda_i, lambda_j, f.density_h.z, mj, s_corr,
                          fluid_spiky_gradient(rij, f.density_h.y), f.density_h.x);
}

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  if (!fluid_particle(i, p.fluid_first, p.fluid_count)) {
    particle_force[i] = vec4(0.0f);  // the rigid particles' reaction: not yet (docs/fluids.md)
    return;
  }
  vec3 xi = xyz(particle_pos[i]);
  FluidMaterial f = fluid_materials[particle_material[i]];
  float lambda_i = fluid_state[i - p.fluid_first].y;
  vec3 dx = vec3(0.0f);
  uint c = neighbour_count[i];
  if (c <= p.neighbour_capacity) {
    for (uint s = 0u; s < c; ++s) {
      dx += shift_term(neighbour_list[s * p.particle_count + i], xi, lambda_i, f);
    }
  } else {
    uint body_i = particle_body[i];
    uint lo[27];
    uint hi[27];
    int ranges = grid_walk(neighbour_ref_pos[i], lo, hi);
    for (int r = 0; r < ranges; ++r) {
      for (uint t = lo[r]; t < hi[r]; ++t) {
        uint j = grid_order[t];
        if (!contact_skipped(body_i, sorted_body[t], i, j)) dx += shift_term(j, xi, lambda_i, f);
      }
    }
  }
  for (uint s = 0u; s < p.plane_count; ++s) {
    vec4 wall = fluid_plane_density(planes[s].normal_offset, xi, f);
    dx += xyz(wall) * (lambda_i * particle_vel[i].w);
  }
  particle_force[i] = vec4(dx, 1.0f);
}
