// The oracle of fluid_update (docs/fluids.md): each fluid particle's correction summed over the
// oracle's own full lists (motes_ref::neighbours_build), in list order, then the planes in order,
// with shared/fluid.h's terms; every solid particle that can move its reaction to its fluid
// neighbours over its list (fluid_solid_reaction, fluid_solid_force); a static particle's 0.
#include "reference.h"
#include "shared/fluid.h"

namespace motes_ref {

using motes::shared::FluidMaterial;
using motes::shared::vec3;

namespace {

bool is_fluid(std::size_t j, const StepParams& p) {
  return j >= p.fluid_first && j < std::size_t{p.fluid_first} + p.fluid_count;
}

// The mass neighbour j counts with in fluid particle i's sums: its fluid material's mass, or
// psi_j = s rho_0 (2 r_j)^3 of i's material for a solid.
float neighbour_mass(const Particles& particles, const std::vector<FluidMaterial>& fluids,
                     std::size_t j, const FluidMaterial& fi, const StepParams& p) {
  if (is_fluid(j, p)) return fluids[particles.material[j]].density_h.z;
  const float d = 2.0f * particles.pos[j].w;
  return fi.s_corr.w * fi.density_h.x * (d * d * d);
}

// Plane k at the particle's centre: its distance z = n . x - offset.
float plane_distance(const PlaneData& plane, vec3 x) {
  const vec4 n = plane.normal_offset;
  return (n.x * x.x + n.y * x.y + n.z * x.z) - n.w;
}

}  // namespace

std::vector<vec4> fluid_update(const Particles& particles, const Neighbours& nb,
                               const std::vector<PlaneData>& planes,
                               const std::vector<FluidMaterial>& fluids,
                               const std::vector<vec4>& state, const StepParams& p) {
  namespace sh = motes::shared;
  std::vector<vec4> out(particles.size(), vec4(0.0f));
  for (std::size_t k = 0; k < p.fluid_count; ++k) {
    const std::size_t i = p.fluid_first + k;
    const FluidMaterial f = fluids[particles.material[i]];
    const float rho0 = f.density_h.x;
    const float h = f.density_h.y;
    const float mi = f.density_h.z;
    const float lambda_i = state[k].y;
    const vec3 xi = sh::xyz(particles.pos[i]);
    vec3 dx(0.0f);
    for (const uint j : nb.lists[i]) {
      const vec3 rij = xi - sh::xyz(particles.pos[j]);
      const bool fluid_j = is_fluid(j, p);
      const float mj = neighbour_mass(particles, fluids, j, f, p);
      const float lambda_j = fluid_j ? state[j - p.fluid_first].y : 0.0f;
      const float s_corr = fluid_j ? sh::fluid_s_corr(sh::dot(rij, rij), mi, f) : 0.0f;
      dx += sh::fluid_shift_term(lambda_i, lambda_j, mi, mj, s_corr,
                                 sh::fluid_spiky_gradient(rij, h), rho0);
    }
    for (const PlaneData& plane : planes) {
      const float z = plane_distance(plane, xi);
      dx += sh::xyz(plane.normal_offset) *
            (sh::fluid_plane_share_slope(z, h) * (lambda_i * particles.vel[i].w));
    }
    out[i] = vec4(dx, 1.0f);
  }
  for (std::size_t b = 0; b < particles.size(); ++b) {
    if (is_fluid(b, p) || particles.vel[b].w == 0.0f) continue;
    const vec3 xb = sh::xyz(particles.pos[b]);
    vec3 reaction(0.0f);
    for (const uint j : nb.lists[b]) {
      if (!is_fluid(j, p)) continue;
      reaction += sh::fluid_solid_reaction(sh::xyz(particles.pos[j]), state[j - p.fluid_first].y,
                                           xb, particles.pos[b].w, fluids[particles.material[j]],
                                           p.gravity_dt.w);
    }
    out[b] = sh::fluid_solid_force(reaction, b < p.rigid_particle_count, particles.vel[b].w,
                                   p.gravity_dt.w);
  }
  return out;
}

}  // namespace motes_ref
