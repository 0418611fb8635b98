// fluid_velocity: one thread per fluid particle; its change of velocity at the velocity level, a
// gather over its neighbours in list order (over capacity: the 27 cells of the last build, whose
// extra particles add zeros): XSPH viscosity, vorticity confinement and cohesion over its fluid
// neighbours within h, adhesion over its solid ones; from the velocities fluid_vorticity copied
// to FluidVelOld, into ParticleVel (w kept; shared/fluid.h). With MOTES_FLAG_FLUID_ADHESION a
// second kernel, a thread per particle: a solid particle that can move takes the reaction to its
// fluid neighbours' adhesion (a rigid one's in ParticleForce, a free one's into its ParticleVel).
// Each thread writes only its own entries. As backends/openmp/fluid_velocity.cpp.
#include "cuda_device.h"
#include "shared/fluid.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

struct FluidVelocityInputs {
  const vec4* __restrict__ pos;
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
  const vec4* __restrict__ vel_old;
  const vec4* __restrict__ aux;
  const vec4* __restrict__ normal;
};

// Calls add(j) for every neighbour j of particle i, in list order (over capacity: the 27 cells).
template <typename F>
__device__ void each_neighbour(const shared::StepParams& p, const FluidVelocityInputs& in, uint i,
                               const F& add) {
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
}

// With MOTES_FLAG_FLUID_ADHESION: every solid particle that can move takes the reaction to its
// fluid neighbours' adhesion (a kernel of its own: the fluid's kernel keeps its registers).
__global__ void fluid_adhesion_reaction_kernel(shared::StepParams p, FluidVelocityInputs in,
                                               vec4* __restrict__ vel, vec4* __restrict__ force) {
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (k >= p.particle_count) return;
  const uint i = uint(k);
  if (shared::fluid_particle(i, p.fluid_first, p.fluid_count)) return;
  const vec4 pb = in.pos[i];
  const vec4 vb = vel[i];
  vec3 reaction(0.0f);
  if (vb.w != 0.0f) {
    each_neighbour(p, in, i, [&](uint j) {
      if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) return;
      reaction += shared::fluid_adhesion_reaction(shared::xyz(in.pos[j]), shared::xyz(pb), pb.w,
                                                  in.fluids[in.material[j]], p.gravity_dt.w);
    });
  }
  const bool rigid = i < p.rigid_particle_count;
  if (rigid) force[i] = vec4(reaction, 0.0f);
  vel[i] = shared::fluid_adhesion_taken(vb, reaction, rigid);
}

__global__ void fluid_velocity_kernel(shared::StepParams p, FluidVelocityInputs in,
                                      vec4* __restrict__ vel) {
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (k >= p.fluid_count) return;
  const uint i = p.fluid_first + uint(k);
  const uint at = uint(k);
  const vec3 xi = shared::xyz(in.pos[i]);
  const shared::FluidMaterial f = in.fluids[in.material[i]];
  const float rho0 = f.density_h.x;
  const float h = f.density_h.y;
  const float hs = p.gravity_dt.w;
  const vec3 vi = shared::xyz(in.vel_old[at]);
  const vec4 omega_i = in.aux[at];
  const vec3 ni = shared::xyz(in.normal[at]);
  const float rhoi = in.state[at].x;
  vec3 xsph(0.0f);
  vec3 eta(0.0f);
  vec3 cohesion(0.0f);
  vec3 adhesion(0.0f);
  const auto add = [&](uint j) {
    const vec3 rij = xi - shared::xyz(in.pos[j]);
    const float r2 = shared::dot(rij, rij);
    if (!shared::fluid_particle(j, p.fluid_first, p.fluid_count)) {
      const float psi = shared::fluid_neighbour_mass(false, 0.0f, in.pos[j].w, f);
      adhesion += shared::fluid_adhesion_term(rij, psi, f.velocity.w, h, hs);
      return;
    }
    if (r2 > h * h) return;
    const uint jk = j - p.fluid_first;
    const float mj = in.fluids[in.material[j]].density_h.z;
    const float rhoj = in.state[jk].x;
    xsph += shared::fluid_xsph_term(vi, shared::xyz(in.vel_old[jk]), mj, rhoi, rhoj, r2, h);
    eta += shared::fluid_eta_term(omega_i.w, in.aux[jk].w, mj, rhoj,
                                  shared::fluid_spiky_gradient(rij, h));
    cohesion += shared::fluid_cohesion_term(rij, mj, rhoi, rhoj, ni, shared::xyz(in.normal[jk]),
                                            rho0, f.velocity.z, h, hs);
  };
  each_neighbour(p, in, i, add);
  vec3 dv =
      xsph * f.velocity.x + shared::fluid_confinement(eta, shared::xyz(omega_i), f.velocity.y, hs);
  dv += cohesion;
  dv += adhesion;
  vel[i] = vec4(vi + dv, vel[i].w);
}

}  // namespace

void CudaDevice::launch_fluid_velocity(const shared::StepParams& p) {
  const bool solids = (p.flags & MOTES_FLAG_FLUID_ADHESION) != 0u;
  if (p.fluid_count == 0 && !(solids && p.particle_count != 0)) return;
  const FluidVelocityInputs in{buf<vec4>(Buffer::ParticlePos),
                               buf<uint>(Buffer::ParticleBody),
                               buf<uint>(Buffer::ParticleMaterial),
                               buf<uint>(Buffer::NeighbourList),
                               buf<uint>(Buffer::NeighbourCount),
                               buf<vec4>(Buffer::NeighbourRefPos),
                               buf<uint>(Buffer::GridOrder),
                               buf<uint>(Buffer::GridCellStart),
                               buf<uint>(Buffer::SortedBody),
                               buf<uint>(Buffer::LinkExclusions),
                               buf<shared::FluidMaterial>(Buffer::FluidMaterials),
                               buf<vec4>(Buffer::FluidState),
                               buf<vec4>(Buffer::FluidVelOld),
                               buf<vec4>(Buffer::FluidAux),
                               buf<vec4>(Buffer::FluidNormal)};
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  if (p.fluid_count != 0) {
    fluid_velocity_kernel<<<blocks_for(p.fluid_count), kBlock, 0, stream_>>>(p, in, vel);
  }
  if (solids && p.particle_count != 0) {  // writes only the solids' entries: no order needed
    fluid_adhesion_reaction_kernel<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(
        p, in, vel, buf<vec4>(Buffer::ParticleForce));
  }
}

}  // namespace motes::cuda
