// The oracle of fluid_vorticity (docs/fluids.md): each fluid particle's vorticity and surface
// normal summed over the fluid particles of the oracle's own full lists
// (motes_ref::neighbours_build), in list order, with shared/fluid.h's terms, and its velocity.
#include "reference.h"
#include "shared/fluid.h"

namespace motes_ref {

using motes::shared::FluidMaterial;
using motes::shared::vec3;

FluidVorticity fluid_vorticity(const Particles& particles, const Neighbours& nb,
                               const std::vector<FluidMaterial>& fluids,
                               const std::vector<vec4>& state, const StepParams& p) {
  namespace sh = motes::shared;
  FluidVorticity out;
  out.vel_old.resize(p.fluid_count);
  out.aux.resize(p.fluid_count);
  out.normal.resize(p.fluid_count);
  for (std::size_t k = 0; k < p.fluid_count; ++k) {
    const std::size_t i = p.fluid_first + k;
    const float h = fluids[particles.material[i]].density_h.y;
    const vec3 xi = sh::xyz(particles.pos[i]);
    const vec3 vi = sh::xyz(particles.vel[i]);
    vec3 omega(0.0f);
    vec3 n(0.0f);
    for (const uint j : nb.lists[i]) {
      if (j < p.fluid_first || j >= std::size_t{p.fluid_first} + p.fluid_count) continue;
      const float mj = fluids[particles.material[j]].density_h.z;
      const float rhoj = state[j - p.fluid_first].x;
      const vec3 grad = sh::fluid_spiky_gradient(xi - sh::xyz(particles.pos[j]), h);
      omega += sh::fluid_vorticity_term(vi, sh::xyz(particles.vel[j]), mj, rhoj, grad);
      n += sh::fluid_normal_term(mj, rhoj, grad, h);
    }
    out.vel_old[k] = vec4(vi, 0.0f);
    out.aux[k] = vec4(omega, sh::sqrt(sh::dot(omega, omega)));
    out.normal[k] = vec4(n, 0.0f);
  }
  return out;
}

}  // namespace motes_ref
