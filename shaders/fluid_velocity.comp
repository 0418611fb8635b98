#version 450
// fluid_velocity: one thread per fluid particle (with MOTES_FLAG_FLUID_ADHESION per particle); a
// fluid particle's change of velocity at the velocity level, a gather over its neighbours in list
// order (over capacity: the 27 cells of the last build, whose extra particles add zeros): XSPH
// viscosity, vorticity confinement and cohesion over its fluid neighbours within h, adhesion over
// its solid ones; from the velocities fluid_vorticity copied to FluidVelOld, into ParticleVel (w
// kept; shared/fluid.h). With the flag a solid particle that can move takes the reaction to its
// fluid neighbours' adhesion (a rigid one's in ParticleForce, a free one's into its ParticleVel).
// Each thread writes only its own entries. As backends/openmp/fluid_velocity.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/fluid.h"
#include "shared/grid_hash.h"
#include "grid_walk.glsl"
#include "link_exclusions.glsl"

// What fluid particle i gathers: the XSPH sum, eta_i, the cohesion and the adhesion sums.
struct Gathered {
  vec3 xsph;
  vec3 eta;
  vec3 cohesion;
  vec3 adhesion;
};

// Particle j's terms of fluid particle i's sums (i's own values from FluidVelOld, FluidAux,
// FluidNormal and FluidState: vi, omega_i.w, ni, rhoi).
void add_neighbour(uint j, vec3 xi, vec3 vi, float wi, vec3 ni, float rhoi, FluidMaterial f,
                   inout Gathered g) {
  float h = f.density_h.y;
  float hs = p.gravity_dt.w;
  vec3 rij = xi - xyz(particle_pos[j]);
  float r2 = dot(rij, rij);
  if (!fluid_particle(j, p.fluid_first, p.fluid_count)) {
    float psi = fluid_neighbour_mass(false, 0.0f, particle_pos[j].w, f);
    g.adhesion += fluid_adhesion_term(rij, psi, f.velocity.w, h, hs);
    return;
  }
  if (r2 > h * h) return;
  uint jk = j - p.fluid_first;
  float mj = fluid_materials[particle_material[j]].density_h.z;
  float rhoj = fluid_state[jk].x;
  g.xsph += fluid_xsph_term(vi, xyz(fluid_vel_old[jk]), mj, rhoi, rhoj, r2, h);
  g.eta += fluid_eta_term(wi, fluid_aux[jk].w, mj, rhoj, fluid_spiky_gradient(rij, h));
  g.cohesion += fluid_cohesion_term(rij, mj, rhoi, rhoj, ni, xyz(fluid_normal[jk]), f.density_h.x,
                                    f.velocity.z, h, hs);
}

// Fluid particle j's part of solid particle b's adhesion reaction (0 for any other j).
vec3 reaction_term(uint j, vec3 xb, float rb) {
  if (!fluid_particle(j, p.fluid_first, p.fluid_count)) return vec3(0.0f);
  return fluid_adhesion_reaction(xyz(particle_pos[j]), xb, rb,
                                 fluid_materials[particle_material[j]], p.gravity_dt.w);
}

// A solid particle's adhesion reaction (a momentum), over the same walk as a fluid particle's.
vec3 adhesion_reaction(uint b) {
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
  bool solids = (p.flags & MOTES_FLAG_FLUID_ADHESION) != 0u;
  uint k = thread_index();
  if (k >= (solids ? p.particle_count : p.fluid_count)) return;
  uint i = (solids ? 0u : p.fluid_first) + k;
  if (!fluid_particle(i, p.fluid_first, p.fluid_count)) {
    vec4 vb = particle_vel[i];
    vec3 reaction = vb.w != 0.0f ? adhesion_reaction(i) : vec3(0.0f);
    bool rigid = i < p.rigid_particle_count;
    if (rigid) particle_force[i] = vec4(reaction, 0.0f);
    particle_vel[i] = fluid_adhesion_taken(vb, reaction, rigid);
    return;
  }
  k = i - p.fluid_first;
  vec3 xi = xyz(particle_pos[i]);
  FluidMaterial f = fluid_materials[particle_material[i]];
  vec3 vi = xyz(fluid_vel_old[k]);
  vec4 omega_i = fluid_aux[k];
  vec3 ni = xyz(fluid_normal[k]);
  float rhoi = fluid_state[k].x;
  Gathered g = Gathered(vec3(0.0f), vec3(0.0f), vec3(0.0f), vec3(0.0f));
  uint c = neighbour_count[i];
  if (c <= p.neighbour_capacity) {
    for (uint s = 0u; s < c; ++s) {
      add_neighbour(list_entry(s, i), xi, vi, omega_i.w, ni, rhoi, f, g);
    }
  } else {
    uint body_i = particle_body[i];
    GridWalk walk = grid_walk_begin(neighbour_ref_pos[i]);
    uint lo, hi;
    while (grid_walk_next(walk, lo, hi)) {
      for (uint t = lo; t < hi; ++t) {
        uint j = grid_order[t];
        if (!contact_skipped(body_i, sorted_body[t], i, j)) {
          add_neighbour(j, xi, vi, omega_i.w, ni, rhoi, f, g);
        }
      }
    }
  }
  vec3 dv = g.xsph * f.velocity.x + fluid_confinement(g.eta, xyz(omega_i), f.velocity.y,
                                                      p.gravity_dt.w);
  dv += g.cohesion;
  dv += g.adhesion;
  particle_vel[i] = vec4(vi + dv, particle_vel[i].w);
}
