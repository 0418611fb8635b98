// fluid_update: every fluid particle's correction dx_i of the density constraint, a gather over
// its neighbour list in list order (over capacity: the 27 cells of the last build, whose extra
// particles beyond h add zeros), then the planes' slope terms, as a shift in ParticleForce
// (w = 1); every solid particle that can move its reaction to its fluid neighbours
// (fluid_solid_reaction over the same walk, written by fluid_solid_force: a rigid particle's for
// its body, a free particle's as its own shift), a static particle's ParticleForce 0
// (shared/fluid.h).
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

void OpenMPDevice::fluid_update(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* vel = buf<vec4>(Buffer::ParticleVel);
  const uint* body = buf<uint>(Buffer::ParticleBody);
  const uint* material = buf<uint>(Buffer::ParticleMaterial);
  const uint* list = buf<uint>(Buffer::NeighbourList);
  const uint* count = buf<uint>(Buffer::NeighbourCount);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  const uint* order = buf<uint>(Buffer::GridOrder);
  const uint* cell_start = buf<uint>(Buffer::GridCellStart);
  const uint* sbody = buf<uint>(Buffer::SortedBody);
  const uint* exclusions = buf<uint>(Buffer::LinkExclusions);
  const auto* planes = buf<shared::PlaneData>(Buffer::Planes);
  const auto* fluids = buf<shared::FluidMaterial>(Buffer::FluidMaterials);
  const vec4* state = buf<vec4>(Buffer::FluidState);
  vec4* force = buf<vec4>(Buffer::ParticleForce);

  const NeighbourWalk walk{list, count, ref, order, cell_start, sbody, body, exclusions};
  const auto each_neighbour = [&](std::size_t i, auto&& add) {
    for_each_neighbour(p, walk, i, add);
  };
  const float hs = p.gravity_dt.w;

  for_items(n, parallel(n), [&](std::int64_t item) {
    const auto i = static_cast<std::size_t>(item);
    const vec4 pi = pos[i];
    const vec3 xi = shared::xyz(pi);
    if (!shared::fluid_particle(uint(i), p.fluid_first, p.fluid_count)) {
      vec3 reaction(0.0f);
      if (vel[i].w != 0.0f) {
        each_neighbour(i, [&](uint j) {
          if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) return;
          reaction += shared::fluid_solid_reaction(shared::xyz(pos[j]), state[j - p.fluid_first].y,
                                                   xi, pi.w, fluids[material[j]], hs);
        });
      }
      force[i] = shared::fluid_solid_force(reaction, i < p.rigid_particle_count, vel[i].w, hs);
      return;
    }
    const shared::FluidMaterial f = fluids[material[i]];
    const float rho0 = f.density_h.x;
    const float h = f.density_h.y;
    const float mi = f.density_h.z;
    const float lambda_i = state[i - p.fluid_first].y;
    vec3 dx(0.0f);
    each_neighbour(i, [&](uint j) {
      const vec3 rij = xi - shared::xyz(pos[j]);
      const bool fluid_j = shared::fluid_particle(j, p.fluid_first, p.fluid_count);
      const float mj =
          shared::fluid_neighbour_mass(fluid_j, fluids[material[j]].density_h.z, pos[j].w, f);
      const float lambda_j = fluid_j ? state[j - p.fluid_first].y : 0.0f;
      const float s_corr = fluid_j ? shared::fluid_s_corr(shared::dot(rij, rij), mi, f) : 0.0f;
      dx += shared::fluid_shift_term(lambda_i, lambda_j, mi, mj, s_corr,
                                     shared::fluid_spiky_gradient(rij, h), rho0);
    });
    for (uint s = 0; s < p.plane_count; ++s) {
      const vec4 wall = shared::fluid_plane_density(planes[s].normal_offset, xi, f);
      dx += shared::xyz(wall) * (lambda_i * vel[i].w);
    }
    force[i] = vec4(dx, 1.0f);
  });
  record(Kernel::FluidUpdate, start);
}

}  // namespace motes::openmp
