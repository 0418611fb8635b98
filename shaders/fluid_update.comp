#version 450
// fluid_update: one thread per particle; a fluid particle's correction dx_i of the density
// constraint, a gather over its neighbour list in list order (over capacity: the 27 cells of the
// last build, whose extra particles beyond h add zeros), then the planes' slope terms, as a shift
// in ParticleForce (w = 1); every solid particle that can move its reaction to its fluid
// neighbours (fluid_solid_reaction over the same walk, fluid_solid_force), a static particle's
// ParticleForce 0 (shared/fluid.h).
// As backends/openmp/fluid_update.cpp.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY
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

// Fluid particle j's part of rigid particle b's reaction (0 for any other j).
vec3 reaction_term(uint j, vec3 xb, float rb) {
  if (!fluid_particle(j, p.fluid_first, p.fluid_count)) return vec3(0.0f);
  return fluid_solid_reaction(xyz(particle_pos[j]), fluid_state[j - p.fluid_first].y, xb, rb,
                              fluid_materials[particle_material[j]], p.gravity_dt.w);
}

// A solid particle's reaction (a momentum), over the same walk as a fluid particle's correction.
vec3 rigid_reaction(uint b) {
  vec3 xb = xyz(particle_pos[b]);
  float rb = particle_pos[b].w;
  vec3 sum = vec3(0.0f);
  uint c = neighbour_count[b];
  if (c <= p.neighbour_capacity) {
    for (uint s = 0u; s < c; ++s) sum += reaction_term(list_entry(s, b), xb, rb);
    return sum;
  }
  uint body_b = particle_body[b];
  GridWalk walk = grid_walk_begin(neighbour_ref_pos[b]);
  uint lo, hi;
  while (grid_walk_next(walk, lo, hi)) {
    for (uint t = lo; t < hi; ++t) {
      uint j = grid_order[t];
      if (!contact_skipped(body_b, sorted_body[t], b, j)) sum += reaction_term(j, xb, rb);
    }
  }
  return sum;
}

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  if (!fluid_particle(i, p.fluid_first, p.fluid_count)) {
    float wi = particle_vel[i].w;
    particle_force[i] = wi != 0.0f ? fluid_solid_force(rigid_reaction(i), i < p.rigid_particle_count,
                                                       wi, p.gravity_dt.w)
                                   : vec4(0.0f);
    return;
  }
  vec3 xi = xyz(particle_pos[i]);
  FluidMaterial f = fluid_materials[particle_material[i]];
  float lambda_i = fluid_state[i - p.fluid_first].y;
  vec3 dx = vec3(0.0f);
  uint c = neighbour_count[i];
  if (c <= p.neighbour_capacity) {
    for (uint s = 0u; s < c; ++s) {
      dx += shift_term(list_entry(s, i), xi, lambda_i, f);
    }
  } else {
    uint body_i = particle_body[i];
    GridWalk walk = grid_walk_begin(neighbour_ref_pos[i]);
    uint lo, hi;
    while (grid_walk_next(walk, lo, hi)) {
      for (uint t = lo; t < hi; ++t) {
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
