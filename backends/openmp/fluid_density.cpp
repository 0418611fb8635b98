// fluid_density: every fluid particle's density rho_i and lambda_i, a gather over its neighbour
// list in list order (a particle over capacity walks the 27 cells of the last build instead: the
// extra particles beyond h add exact zeros), then the planes in order (shared/fluid.h).
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

void OpenMPDevice::fluid_density(const shared::StepParams& p) {
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
  const auto* planes = buf<shared::PlaneData>(Buffer::Planes);
  const auto* fluids = buf<shared::FluidMaterial>(Buffer::FluidMaterials);
  vec4* state = buf<vec4>(Buffer::FluidState);
  const bool first = (p.flags & MOTES_FLAG_POSITION_FIRST) != 0u;

  const NeighbourWalk walk{list, count, ref, order, cell_start, sbody, body, exclusions};
  for_items(n, parallel_heavy(n), [&](std::int64_t k) {
    const auto i = static_cast<std::size_t>(p.fluid_first + static_cast<uint>(k));
    const vec4 pi = pos[i];
    const vec3 xi = shared::xyz(pi);
    const shared::FluidMaterial f = fluids[material[i]];
    const float rho0 = f.density_h.x;
    const float h = f.density_h.y;
    float rho = f.density_h.z * shared::fluid_poly6(0.0f, h);
    vec4 gathered(0.0f);
    auto add = [&](uint j) {
      const vec3 rij = xi - shared::xyz(pos[j]);
      const bool fluid_j = shared::fluid_particle(j, p.fluid_first, p.fluid_count);
      const float mj =
          shared::fluid_neighbour_mass(fluid_j, fluids[material[j]].density_h.z, pos[j].w, f);
      rho += mj * shared::fluid_poly6(shared::dot(rij, rij), h);
      gathered += shared::fluid_gradient_term(rij, mj, fluid_j ? vel[j].w : 0.0f, rho0, h);
    };
    for_each_neighbour(p, walk, i, add);
    for (uint s = 0; s < p.plane_count; ++s) {
      const vec4 wall = shared::fluid_plane_density(planes[s].normal_offset, xi, f);
      rho += wall.w;
      gathered += vec4(shared::xyz(wall), 0.0f);
    }
    const float lambda = shared::fluid_lambda(shared::fluid_constraint(rho, rho0, true), gathered,
                                              vel[i].w, f.density_h.w);
    const std::size_t at = static_cast<std::size_t>(k);
    state[at] = vec4(rho, lambda, first ? lambda : state[at].z + lambda, 0.0f);
  });
  record(Kernel::FluidDensity, start);
}

}  // namespace motes::openmp
