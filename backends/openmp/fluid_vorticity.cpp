// fluid_vorticity: every fluid particle's vorticity omega_i and surface normal n_i, a gather over
// its fluid neighbours in list order (solids skipped; over capacity: the 27 cells of the last
// build, whose extra particles beyond h add zeros), and a copy of its velocity for the velocity
// pass (shared/fluid.h).
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

void OpenMPDevice::fluid_vorticity(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(p.fluid_count);
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
  const auto* fluids = buf<shared::FluidMaterial>(Buffer::FluidMaterials);
  const vec4* state = buf<vec4>(Buffer::FluidState);
  vec4* vel_old = buf<vec4>(Buffer::FluidVelOld);
  vec4* aux = buf<vec4>(Buffer::FluidAux);
  vec4* normal = buf<vec4>(Buffer::FluidNormal);

  const NeighbourWalk walk{list, count, ref, order, cell_start, sbody, body, exclusions};
  for_items(n, parallel_heavy(n), [&](std::int64_t k) {
    const auto i = static_cast<std::size_t>(p.fluid_first + static_cast<uint>(k));
    const vec3 xi = shared::xyz(pos[i]);
    const vec3 vi = shared::xyz(vel[i]);
    const float h = fluids[material[i]].density_h.y;
    vec3 omega(0.0f);
    vec3 ni(0.0f);
    auto add = [&](uint j) {
      if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) return;
      const vec3 grad = shared::fluid_spiky_gradient(xi - shared::xyz(pos[j]), h);
      const float mj = fluids[material[j]].density_h.z;
      const float rhoj = state[j - p.fluid_first].x;
      omega += shared::fluid_vorticity_term(vi, shared::xyz(vel[j]), mj, rhoj, grad);
      ni += shared::fluid_normal_term(mj, rhoj, grad, h);
    };
    for_each_neighbour(p, walk, i, add);
    const std::size_t at = static_cast<std::size_t>(k);
    vel_old[at] = vec4(vi, 0.0f);
    aux[at] = vec4(omega, shared::sqrt(shared::dot(omega, omega)));
    normal[at] = vec4(ni, 0.0f);
  });
  record(Kernel::FluidVorticity, start);
}

}  // namespace motes::openmp
