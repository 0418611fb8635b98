// The oracle of fluid_density (docs/fluids.md): each fluid particle's density and lambda summed
// over the oracle's own full lists (motes_ref::neighbours_build), in list order, then the planes
// in order, with shared/fluid.h's terms.
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

std::vector<vec4> fluid_density(const Particles& particles, const Neighbours& nb,
                                const std::vector<PlaneData>& planes,
                                const std::vector<FluidMaterial>& fluids,
                                const std::vector<vec4>& state, const StepParams& p) {
  namespace sh = motes::shared;
  std::vector<vec4> out(p.fluid_count);
  for (std::size_t k = 0; k < p.fluid_count; ++k) {
    const std::size_t i = p.fluid_first + k;
    const FluidMaterial f = fluids[particles.material[i]];
    const float rho0 = f.density_h.x;
    const float h = f.density_h.y;
    const vec3 xi = sh::xyz(particles.pos[i]);
    float rho = f.density_h.z * sh::fluid_poly6(0.0f, h);
    vec4 gathered(0.0f);
    for (const uint j : nb.lists[i]) {
      const vec3 rij = xi - sh::xyz(particles.pos[j]);
      const float mj = neighbour_mass(particles, fluids, j, f, p);
      rho += mj * sh::fluid_poly6(sh::dot(rij, rij), h);
      gathered +=
          sh::fluid_gradient_term(rij, mj, is_fluid(j, p) ? particles.vel[j].w : 0.0f, rho0, h);
    }
    for (const PlaneData& plane : planes) {
      const float z = plane_distance(plane, xi);
      const vec3 n = sh::xyz(plane.normal_offset);
      rho += rho0 * sh::fluid_plane_share(z, h);
      gathered += vec4(n * sh::fluid_plane_share_slope(z, h), 0.0f);
    }
    const float c = sh::fluid_constraint(rho, rho0, true);
    const float lambda = sh::fluid_lambda(c, gathered, particles.vel[i].w, f.density_h.w);
    const bool first = (p.flags & MOTES_FLAG_POSITION_FIRST) != 0u;
    out[k] = vec4(rho, lambda, first ? lambda : state[k].z + lambda, 0.0f);
  }
  return out;
}

}  // namespace motes_ref
