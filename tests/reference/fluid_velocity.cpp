// The oracle of fluid_velocity (docs/fluids.md): each fluid particle's change of velocity summed
// over the oracle's own full lists (motes_ref::neighbours_build), in list order, with
// shared/fluid.h's terms: XSPH, eta (for the confinement) and cohesion over the fluid neighbours
// within h, adhesion over the solid ones; every other particle's velocity as it was, or with
// MOTES_FLAG_FLUID_ADHESION every solid particle that can move its reaction to its fluid
// neighbours' adhesion (a rigid one's in `force`, a free one's into its velocity).
#include "reference.h"
#include "shared/fluid.h"

namespace motes_ref {

using motes::shared::FluidMaterial;
using motes::shared::vec3;

std::vector<vec4> fluid_velocity(const Particles& particles, const Neighbours& nb,
                                 const std::vector<FluidMaterial>& fluids,
                                 const std::vector<vec4>& state, const FluidVorticity& vort,
                                 const StepParams& p, std::vector<vec4>* force) {
  namespace sh = motes::shared;
  std::vector<vec4> out = particles.vel;
  const float hs = p.gravity_dt.w;
  const auto fluid = [&](uint j) {
    return j >= p.fluid_first && j < std::size_t{p.fluid_first} + p.fluid_count;
  };
  if ((p.flags & MOTES_FLAG_FLUID_ADHESION) != 0u) {
    for (uint b = 0; b < p.particle_count; ++b) {
      if (fluid(b)) continue;
      const vec4 pb = particles.pos[b];
      vec3 reaction(0.0f);
      if (particles.vel[b].w != 0.0f) {
        for (const uint j : nb.lists[b]) {
          if (!fluid(j)) continue;
          reaction += sh::fluid_adhesion_reaction(sh::xyz(particles.pos[j]), sh::xyz(pb), pb.w,
                                                  fluids[particles.material[j]], hs);
        }
      }
      const bool rigid = b < p.rigid_particle_count;
      if (rigid && force != nullptr) (*force)[b] = vec4(reaction, 0.0f);
      out[b] = sh::fluid_adhesion_taken(particles.vel[b], reaction, rigid);
    }
  }
  for (std::size_t k = 0; k < p.fluid_count; ++k) {
    const std::size_t i = p.fluid_first + k;
    const FluidMaterial f = fluids[particles.material[i]];
    const float rho0 = f.density_h.x;
    const float h = f.density_h.y;
    const float c = f.velocity.x;
    const float eps = f.velocity.y;
    const float gamma = f.velocity.z;
    const float beta = f.velocity.w;
    const vec3 xi = sh::xyz(particles.pos[i]);
    const vec3 vi = sh::xyz(vort.vel_old[k]);
    const vec3 omega_i = sh::xyz(vort.aux[k]);
    const float omega_len_i = vort.aux[k].w;
    const vec3 ni = sh::xyz(vort.normal[k]);
    const float rhoi = state[k].x;
    vec3 xsph(0.0f);
    vec3 eta(0.0f);
    vec3 cohesion(0.0f);
    vec3 adhesion(0.0f);
    for (const uint j : nb.lists[i]) {
      const vec3 rij = xi - sh::xyz(particles.pos[j]);
      const float r2 = sh::dot(rij, rij);
      if (!fluid(j)) {
        const float d = 2.0f * particles.pos[j].w;
        const float psi = f.s_corr.w * rho0 * (d * d * d);
        adhesion += sh::fluid_adhesion_term(rij, psi, beta, h, hs);
        continue;
      }
      if (r2 > h * h) continue;
      const std::size_t jk = j - p.fluid_first;
      const float mj = fluids[particles.material[j]].density_h.z;
      const float rhoj = state[jk].x;
      xsph += sh::fluid_xsph_term(vi, sh::xyz(vort.vel_old[jk]), mj, rhoi, rhoj, r2, h);
      eta += sh::fluid_eta_term(omega_len_i, vort.aux[jk].w, mj, rhoj,
                                sh::fluid_spiky_gradient(rij, h));
      cohesion += sh::fluid_cohesion_term(rij, mj, rhoi, rhoj, ni, sh::xyz(vort.normal[jk]), rho0,
                                          gamma, h, hs);
    }
    vec3 dv = xsph * c + sh::fluid_confinement(eta, omega_i, eps, hs);
    dv += cohesion;
    dv += adhesion;
    out[i] = vec4(vi + dv, particles.vel[i].w);
  }
  return out;
}

}  // namespace motes_ref
