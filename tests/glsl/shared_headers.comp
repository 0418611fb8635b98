#version 450
// Compiles every header of shaders/shared/ as GLSL: the physics is written once for C++, CUDA and
// GLSL, and this keeps the GLSL side honest in builds without the Vulkan backend (whose shaders
// use every header and are compiled and validated by the build itself).
#extension GL_GOOGLE_include_directive : require

#include "shared/common.h"
#include "shared/params.h"
#include "shared/grid_hash.h"
#include "shared/quaternion.h"
#include "shared/contact_force.h"
#include "shared/body_math.h"
#include "shared/links.h"
#include "shared/neighbours.h"
#include "shared/halo.h"
#include "shared/energy.h"
#include "shared/fluid.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { StepParams p; };
layout(std430, binding = 0) buffer Pos { vec4 pos[]; };
layout(std430, binding = 1) buffer Vel { vec4 vel[]; };
layout(std430, binding = 2) buffer Laws { ContactLaw laws[]; };
layout(std430, binding = 3) buffer Planes { PlaneData planes[]; };
layout(std430, binding = 4) buffer Out { vec4 result[]; };
layout(std430, binding = 5) buffer Fluids { FluidMaterial fluids[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= p.particle_count) return;
  vec4 a = pos[i];
  vec4 b = pos[(i + 1u) % p.particle_count];
  vec3 f = particle_contact_force(xyz(a), xyz(vel[i]), a.w, vel[i].w, xyz(b), xyz(b), b.w, 1.0f,
                                  laws[0], p.flags);
  f += plane_contact_force(xyz(a), xyz(vel[i]), a.w, vel[i].w, planes[0].normal_offset, laws[0],
                           p.flags);
  uint bucket = grid_bucket(grid_cell_coord(a.x, p.inv_cell_size), 0, 0, p.table_mask);
  vec4 q = vec4(0.0f, 0.0f, 0.0f, 1.0f);
  vec4 body = a;
  vec4 v = vel[i];
  vec4 l = vec4(1.0f, 0.0f, 0.0f, 0.0f);
  vec4 w;
  body_integrate(body, q, v, l, w, vec4(1.0f), vec4(f, 0.0f), vec4(0.0f), p.gravity_dt, p.flags);
  vec3 x = particle_position(body, q, a) + particle_velocity(q, v, w, a);
  vec3 e = item_energy(a, v, v.w, true, w, l, p.gravity_dt, xyz(b));
  FluidMaterial fm = fluids[0];
  vec3 rij = xyz(a) - xyz(b);
  vec3 g = fluid_spiky_gradient(rij, fm.density_h.y);
  vec4 gt = fluid_gradient_term(rij, fm.density_h.z, 1.0f / fm.density_h.z, fm.density_h.x,
                                fm.density_h.y);
  float lambda = fluid_lambda(fluid_constraint(fluid_poly6(dot(rij, rij), fm.density_h.y) +
                                                   fluid_spiky(length(rij), fm.density_h.y),
                                               fm.density_h.x, true),
                              gt, 1.0f / fm.density_h.z, fm.density_h.w);
  vec3 fl = fluid_shift_term(lambda, lambda, fm.density_h.z, fm.density_h.z,
                             fluid_s_corr(dot(rij, rij), fm.density_h.z, fm), g, fm.density_h.x) +
            fluid_rigid_reaction(g, fm.density_h.z, p.gravity_dt.w) +
            fluid_xsph_term(xyz(v), xyz(vel[i]), 1.0f, 1.0f, 1.0f, 0.0f, fm.density_h.y) +
            fluid_confinement(fluid_eta_term(1.0f, 2.0f, 1.0f, 1.0f, g),
                              fluid_vorticity_term(xyz(v), xyz(vel[i]), 1.0f, 1.0f, g), 1.0f,
                              p.gravity_dt.w) +
            fluid_cohesion_term(rij, 1.0f, 1.0f, 1.0f, fluid_normal_term(1.0f, 1.0f, g, 1.0f), g,
                                1.0f, fm.velocity.z, fm.density_h.y, p.gravity_dt.w) +
            fluid_adhesion_term(rij, 1.0f, fm.velocity.w, fm.density_h.y, p.gravity_dt.w) *
                fluid_pressure(lambda, 1.0f, 1.0f, 1.0f) +
            fluid_gradient_moment_term(rij, 1.0f, 1.0f, fm.density_h.y) +
            g * (fluid_plane_share(a.y, fm.density_h.y) +
                 fluid_plane_share_slope(a.y, fm.density_h.y));
  result[i] = vec4(x + particle_torque(a, body, vec4(f, 0.0f)) + e + fl,
                   float(bucket) + uintBitsToFloat(displacement2_bits(a, b)) +
                       float(energy_blocks(energy_items(p.body_count, p.particle_count,
                                                        p.rigid_particle_count))) +
                       (energy_larger(e.x, 1u, e.y, 2u) ? bits_float(1u) : 0.0f));
}
