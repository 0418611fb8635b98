// fluid_vorticity: one thread per fluid particle; its vorticity omega_i and surface normal n_i, a
// gather over its fluid neighbours in list order (solids skipped; over capacity: the 27 cells of
// the last build, whose extra particles beyond h add zeros), and a copy of its velocity for the
// velocity pass (shared/fluid.h). Each thread writes only its own entries. As
// backends/openmp/fluid_vorticity.cpp.
#include "cuda_device.h"
#include "shared/fluid.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

struct FluidVorticityInputs {
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
  const shared::FluidMaterial* __restrict__ fluids;
  const vec4* __restrict__ state;
};

struct FluidVorticityOutputs {
  vec4* __restrict__ vel_old;
  vec4* __restrict__ aux;
  vec4* __restrict__ normal;
};

__global__ void fluid_vorticity_kernel(shared::StepParams p, FluidVorticityInputs in,
                                       FluidVorticityOutputs out) {
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (k >= p.fluid_count) return;
  const uint i = p.fluid_first + uint(k);
  const vec3 xi = shared::xyz(in.pos[i]);
  const vec3 vi = shared::xyz(in.vel[i]);
  const float h = in.fluids[in.material[i]].density_h.y;
  vec3 omega(0.0f);
  vec3 ni(0.0f);
  const auto add = [&](uint j) {
    if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) return;
    const vec3 grad = shared::fluid_spiky_gradient(xi - shared::xyz(in.pos[j]), h);
    const float mj = in.fluids[in.material[j]].density_h.z;
    const float rhoj = in.state[j - p.fluid_first].x;
    omega += shared::fluid_vorticity_term(vi, shared::xyz(in.vel[j]), mj, rhoj, grad);
    ni += shared::fluid_normal_term(mj, rhoj, grad, h);
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
  out.vel_old[k] = vec4(vi, 0.0f);
  out.aux[k] = vec4(omega, shared::sqrt(shared::dot(omega, omega)));
  out.normal[k] = vec4(ni, 0.0f);
}

}  // namespace

void CudaDevice::launch_fluid_vorticity(const shared::StepParams& p) {
  if (p.fluid_count == 0) return;
  const FluidVorticityInputs in{
      buf<vec4>(Buffer::ParticlePos),     buf<vec4>(Buffer::ParticleVel),
      buf<uint>(Buffer::ParticleBody),    buf<uint>(Buffer::ParticleMaterial),
      buf<uint>(Buffer::NeighbourList),   buf<uint>(Buffer::NeighbourCount),
      buf<vec4>(Buffer::NeighbourRefPos), buf<uint>(Buffer::GridOrder),
      buf<uint>(Buffer::GridCellStart),   buf<uint>(Buffer::SortedBody),
      buf<uint>(Buffer::LinkExclusions),  buf<shared::FluidMaterial>(Buffer::FluidMaterials),
      buf<vec4>(Buffer::FluidState)};
  const FluidVorticityOutputs out{buf<vec4>(Buffer::FluidVelOld), buf<vec4>(Buffer::FluidAux),
                                  buf<vec4>(Buffer::FluidNormal)};
  fluid_vorticity_kernel<<<blocks_for(p.fluid_count), kBlock, 0, stream_>>>(p, in, out);
}

}  // namespace motes::cuda
