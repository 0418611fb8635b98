#version 450
// fluid_velocity: one thread per fluid particle; its change of velocity at the velocity level, a
// gather over its neighbours in list order (over capacity: the 27 cells of the last build, whose
// extra particles add zeros): XSPH viscosity, vorticity confinement and cohesion over its fluid
// neighbours within h, adhesion over its solid ones; from the velocities fluid_vorticity copied
// to FluidVelOld, into ParticleVel (w kept; shared/fluid.h). Each thread reads and writes only its
// own ParticleVel entry. As backends/openmp/fluid_velocity.cpp.
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

void main() {
  uint k = thread_index();
  if (k >= p.fluid_count) return;
  uint i = p.fluid_first + k;
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
      add_neighbour(neighbour_list[s * p.particle_count + i], xi, vi, omega_i.w, ni, rhoi, f, g);
    }
  } else {
    uint body_i = particle_body[i];
    uint lo[27];
    uint hi[27];
    int ranges = grid_walk(neighbour_ref_pos[i], lo, hi);
    for (int r = 0; r < ranges; ++r) {
      for (uint t = lo[r]; t < hi[r]; ++t) {
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
