// fluid_density: one thread per fluid particle; its density and lambda, a gather over its
// neighbour list in list order (over capacity: the 27 cells of the last build, whose extra
// particles beyond h add zeros), then the planes in order (shared/fluid.h). Each thread writes
// only its own FluidState entry. As backends/openmp/fluid_density.cpp.
#include "cuda_device.h"
#include "shared/fluid.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

struct FluidDensityInputs {
  const vec4* __restrict__ pos;
  const vec4* __restrict__ vel;
  const uint* __restrict__ body;
  const uint* __restrict__ material;
  const uint* __restrict__ list;
  const uint* __restrict__ count;
  const vec4* __restrict__ ref;
  const uint* __restrict__ order;
  const uint* __restrict__ cell_start;
  const uint* __restrict__ sbody;
  const uint* exclusions;
  const shared::PlaneData* __restrict__ planes;
  const shared::FluidMaterial* __restrict__ fluids;
};

__global__ void fluid_density_kernel(shared::StepParams p, FluidDensityInputs in,
                                     vec4* __restrict__ state) {
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (k >= p.fluid_count) return;
  const uint i = p.fluid_first + uint(k);
  const vec3 xi = shared::xyz(in.pos[i]);
  const shared::FluidMaterial f = in.fluids[in.material[i]];
  const float rho0 = f.density_h.x;
  const float h = f.density_h.y;
  float rho = f.density_h.z * shared::fluid_poly6(0.0f, h);
  vec4 gathered(0.0f);
  const auto add = [&](uint j) {
    const vec3 rij = xi - shared::xyz(in.pos[j]);
    const bool fluid_j = shared::fluid_particle(j, p.fluid_first, p.fluid_count);
    const float mj = shared::fluid_neighbour_mass(fluid_j, in.fluids[in.material[j]].density_h.z,
                                                  in.pos[j].w, f);
    rho += mj * shared::fluid_poly6(shared::dot(rij, rij), h);
    gathered += shared::fluid_gradient_term(rij, mj, fluid_j ? in.vel[j].w : 0.0f, rho0, h);
  };
  const uint c = in.count[i];
  if (c <= p.neighbour_capacity) {
    const std::size_t stride = p.particle_count;
    for (uint s = 0; s < c; ++s) add(in.list[std::size_t{s} * stride + i]);
  } else {
    const uint body_i = in.body[i];
    shared::grid_walk(p, in.ref[i], in.cell_start, [&](uint lo, uint hi) {
      for (uint t = lo; t < hi; ++t) {
        const uint j = in.order[t];
        if (!shared::contact_skipped(body_i, in.sbody[t], i, j, in.exclusions, p.particle_count,
                                     p.linked_first)) {
          add(j);
        }
      }
    });
  }
  for (uint s = 0; s < p.plane_count; ++s) {
    const vec4 wall = shared::fluid_plane_density(in.planes[s].normal_offset, xi, f);
    rho += wall.w;
    gathered += vec4(shared::xyz(wall), 0.0f);
  }
  const float lambda = shared::fluid_lambda(shared::fluid_constraint(rho, rho0, true), gathered,
                                            in.vel[i].w, f.density_h.w);
  const bool first = (p.flags & MOTES_FLAG_POSITION_FIRST) != 0u;
  state[k] = vec4(rho, lambda, first ? lambda : state[k].z + lambda, 0.0f);
}

}  // namespace

void CudaDevice::launch_fluid_density(const shared::StepParams& p) {
  if (p.fluid_count == 0) return;
  const FluidDensityInputs in{buf<vec4>(Buffer::ParticlePos),
                              buf<vec4>(Buffer::ParticleVel),
                              buf<uint>(Buffer::ParticleBody),
                              buf<uint>(Buffer::ParticleMaterial),
                              buf<uint>(Buffer::NeighbourList),
                              buf<uint>(Buffer::NeighbourCount),
                              buf<vec4>(Buffer::NeighbourRefPos),
                              buf<uint>(Buffer::GridOrder),
                              buf<uint>(Buffer::GridCellStart),
                              buf<uint>(Buffer::SortedBody),
                              buf<uint>(Buffer::LinkExclusions),
                              buf<shared::PlaneData>(Buffer::Planes),
                              buf<shared::FluidMaterial>(Buffer::FluidMaterials)};
  fluid_density_kernel<<<blocks_for(p.fluid_count), kBlock, 0, stream_>>>(
      p, in, buf<vec4>(Buffer::FluidState));
}

}  // namespace motes::cuda
