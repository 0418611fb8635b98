// fluid_update: one thread per particle; a fluid particle's correction dx_i of the density
// constraint, a gather over its neighbour list in list order (over capacity: the 27 cells of the
// last build, whose extra particles beyond h add zeros), then the planes' slope terms, as a shift
// in ParticleForce (w = 1); every solid particle that can move its reaction to its fluid
// neighbours (fluid_solid_reaction over the same walk, fluid_solid_force), a static particle's
// ParticleForce 0 (shared/fluid.h).
// As backends/openmp/fluid_update.cpp.
#include "cuda_device.h"
#include "shared/fluid.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

struct FluidUpdateInputs {
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
  const vec4* __restrict__ state;
};

__global__ void fluid_update_kernel(shared::StepParams p, FluidUpdateInputs in,
                                    vec4* __restrict__ force) {
  const std::uint64_t item = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (item >= p.particle_count) return;
  const uint i = uint(item);
  // Particle i's neighbours, in list order (over capacity: the 27 cells of the last build).
  const auto each_neighbour = [&](auto&& add) {
    const uint c = in.count[i];
    if (c <= p.neighbour_capacity) {
      const std::size_t stride = p.particle_count;
      for (uint s = 0; s < c; ++s) add(in.list[std::size_t{s} * stride + i]);
      return;
    }
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
  };
  const vec4 pi = in.pos[i];
  const vec3 xi = shared::xyz(pi);
  if (!shared::fluid_particle(i, p.fluid_first, p.fluid_count)) {
    vec3 reaction(0.0f);
    if (in.vel[i].w != 0.0f) {
      each_neighbour([&](uint j) {
        if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) return;
        reaction +=
            shared::fluid_solid_reaction(shared::xyz(in.pos[j]), in.state[j - p.fluid_first].y, xi,
                                         pi.w, in.fluids[in.material[j]], p.gravity_dt.w);
      });
    }
    force[i] = shared::fluid_solid_force(reaction, i < p.rigid_particle_count, in.vel[i].w,
                                         p.gravity_dt.w);
    return;
  }
  const shared::FluidMaterial f = in.fluids[in.material[i]];
  const float rho0 = f.density_h.x;
  const float h = f.density_h.y;
  const float mi = f.density_h.z;
  const float lambda_i = in.state[i - p.fluid_first].y;
  vec3 dx(0.0f);
  each_neighbour([&](uint j) {
    const vec3 rij = xi - shared::xyz(in.pos[j]);
    const bool fluid_j = shared::fluid_particle(j, p.fluid_first, p.fluid_count);
    const float mj = shared::fluid_neighbour_mass(fluid_j, in.fluids[in.material[j]].density_h.z,
                                                  in.pos[j].w, f);
    const float lambda_j = fluid_j ? in.state[j - p.fluid_first].y : 0.0f;
    const float s_corr = fluid_j ? shared::fluid_s_corr(shared::dot(rij, rij), mi, f) : 0.0f;
    dx += shared::fluid_shift_term(lambda_i, lambda_j, mi, mj, s_corr,
                                   shared::fluid_spiky_gradient(rij, h), rho0);
  });
  for (uint s = 0; s < p.plane_count; ++s) {
    const vec4 wall = shared::fluid_plane_density(in.planes[s].normal_offset, xi, f);
    dx += shared::xyz(wall) * (lambda_i * in.vel[i].w);
  }
  force[i] = vec4(dx, 1.0f);
}

}  // namespace

void CudaDevice::launch_fluid_update(const shared::StepParams& p) {
  if (p.particle_count == 0) return;
  const FluidUpdateInputs in{buf<vec4>(Buffer::ParticlePos),
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
                             buf<shared::FluidMaterial>(Buffer::FluidMaterials),
                             buf<vec4>(Buffer::FluidState)};
  fluid_update_kernel<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(
      p, in, buf<vec4>(Buffer::ParticleForce));
}

}  // namespace motes::cuda
