// The entries of halo_pack and halo_unpack (shared/halo.h): the grid-stride loop both kernels
// run over them, the particle entries first, then the rigid body entries.
#pragma once

#include <cstdint>

#include "shared/halo.h"
#include "shared/params.h"

namespace motes::cuda {

/// Calls particle(t, i) for each particle entry t whose index i is a particle, and body(at, i) for
/// each rigid body entry whose index i is a body, `at` its first vec4 in HaloData; an entry whose
/// index is out of range is skipped.
template <typename Particle, typename Body>
__device__ void halo_entries(const shared::StepParams& p, const shared::uint* __restrict__ index,
                             Particle&& particle, Body&& body) {
  const std::uint64_t np = p.halo_particles;
  const std::uint64_t total = np + p.halo_bodies;
  const std::uint64_t stride = std::uint64_t{gridDim.x} * blockDim.x;
  for (std::uint64_t t = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x; t < total;
       t += stride) {
    const shared::uint i = index[p.halo_first + t];
    if (t < np) {
      if (i < p.particle_count) particle(t, i);
    } else if (i < p.body_count) {
      body(MOTES_HALO_PARTICLE_VEC4S * np + MOTES_HALO_BODY_VEC4S * (t - np), i);
    }
  }
}

}  // namespace motes::cuda
