// fluid_velocity: every fluid particle's change of velocity at the velocity level, a gather over
// its neighbours in list order (over capacity: the 27 cells of the last build, whose extra
// particles add zeros): XSPH viscosity, vorticity confinement and cohesion over its fluid
// neighbours within h, adhesion over its solid ones; from the velocities fluid_vorticity copied to
// FluidVelOld, into ParticleVel (w kept; shared/fluid.h). With MOTES_FLAG_FLUID_ADHESION every
// solid particle that can move takes the reaction to its fluid neighbours' adhesion over the same
// walk (fluid_adhesion_reaction): a rigid particle's in ParticleForce for its body, a free one's
// into its ParticleVel (fluid_adhesion_taken).
#include <chrono>
#include <cstdint>

#include "fluid_walk.h"
#include "openmp_device.h"
#include "shared/fluid.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::fluid_velocity(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const bool solids = (p.flags & MOTES_FLAG_FLUID_ADHESION) != 0u;
  const auto n = static_cast<std::int64_t>(solids ? p.particle_count : p.fluid_count);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const uint* body = buf<uint>(Buffer::ParticleBody);
  const uint* material = buf<uint>(Buffer::ParticleMaterial);
  const uint* list = buf<uint>(Buffer::NeighbourList);
  const uint* count = buf<uint>(Buffer::NeighbourCount);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  const uint* order = buf<uint>(Buffer::GridOrder);
  const uint* cell_start = buf<uint>(Buffer::GridCellStart);
  const uint* sbody = buf<uint>(Buffer::SortedBody);
  const uint* exclusions = buf<uint>(Buffer::LinkExclusions);
  const auto* fluids = buf<shared::FluidMaterial>(Buffer::FluidMaterials);
  const vec4* state = buf<vec4>(Buffer::FluidState);
  const vec4* vel_old = buf<vec4>(Buffer::FluidVelOld);
  const vec4* aux = buf<vec4>(Buffer::FluidAux);
  const vec4* normal = buf<vec4>(Buffer::FluidNormal);
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  vec4* force = buf<vec4>(Buffer::ParticleForce);
  const float hs = p.gravity_dt.w;

  const NeighbourWalk walk{list, count, ref, order, cell_start, sbody, body, exclusions};
  for_items(n, parallel_heavy(n), [&](std::int64_t item) {
    const auto i =
        static_cast<std::size_t>(solids ? 0u : p.fluid_first) + static_cast<std::size_t>(item);
    if (!shared::fluid_particle(uint(i), p.fluid_first, p.fluid_count)) {
      const vec4 pb = pos[i];
      vec3 reaction(0.0f);
      if (vel[i].w != 0.0f) {
        for_each_neighbour(p, walk, i, [&](uint j) {
          if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) return;
          reaction += shared::fluid_adhesion_reaction(shared::xyz(pos[j]), shared::xyz(pb), pb.w,
                                                      fluids[material[j]], hs);
        });
      }
      const bool rigid = i < p.rigid_particle_count;
      if (rigid) force[i] = vec4(reaction, 0.0f);
      vel[i] = shared::fluid_adhesion_taken(vel[i], reaction, rigid);
      return;
    }
    const std::size_t at = i - p.fluid_first;
    const vec3 xi = shared::xyz(pos[i]);
    const shared::FluidMaterial f = fluids[material[i]];
    const float rho0 = f.density_h.x;
    const float h = f.density_h.y;
    const vec3 vi = shared::xyz(vel_old[at]);
    const vec4 omega_i = aux[at];
    const vec3 ni = shared::xyz(normal[at]);
    const float rhoi = state[at].x;
    vec3 xsph(0.0f);
    vec3 eta(0.0f);
    vec3 cohesion(0.0f);
    vec3 adhesion(0.0f);
    auto add = [&](uint j) {
      const vec3 rij = xi - shared::xyz(pos[j]);
      const float r2 = shared::dot(rij, rij);
      if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) {
        const float psi = shared::fluid_neighbour_mass(false, 0.0f, pos[j].w, f);
        adhesion += shared::fluid_adhesion_term(rij, psi, f.velocity.w, h, hs);
        return;
      }
      if (r2 > h * h) return;
      const std::size_t jk = j - p.fluid_first;
      const float mj = fluids[material[j]].density_h.z;
      const float rhoj = state[jk].x;
      xsph += shared::fluid_xsph_term(vi, shared::xyz(vel_old[jk]), mj, rhoi, rhoj, r2, h);
      eta += shared::fluid_eta_term(omega_i.w, aux[jk].w, mj, rhoj,
                                    shared::fluid_spiky_gradient(rij, h));
      cohesion += shared::fluid_cohesion_term(rij, mj, rhoi, rhoj, ni, shared::xyz(normal[jk]),
                                              rho0, f.velocity.z, h, hs);
    };
    for_each_neighbour(p, walk, i, add);
    vec3 dv = xsph * f.velocity.x +
              shared::fluid_confinement(eta, shared::xyz(omega_i), f.velocity.y, hs);
    dv += cohesion;
    dv += adhesion;
    vel[i] = vec4(vi + dv, vel[i].w);
  });
  record(Kernel::FluidVelocity, start);
}

}  // namespace motes::openmp
