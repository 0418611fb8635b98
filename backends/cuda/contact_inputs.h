// The buffers a particle's contacts are found and evaluated from, gathered once for the launches
// of contacts_compute and impulses_compute: the particles' position, velocity, body and material,
// the neighbour lists, the grid of the last build (walked instead by a particle with more
// neighbours than its list holds), the contact laws and the planes.
#pragma once

#include "shared/params.h"

namespace motes::cuda {

struct ContactInputs {
  const shared::vec4* __restrict__ pos;          ///< ParticlePos
  const shared::vec4* __restrict__ vel;          ///< ParticleVel
  const shared::uint* __restrict__ body;         ///< ParticleBody
  const shared::uint* __restrict__ material;     ///< ParticleMaterial
  const shared::uint* __restrict__ list;         ///< NeighbourList: entry k of i at k * N + i
  const shared::uint* __restrict__ count;        ///< NeighbourCount
  const shared::vec4* __restrict__ ref;          ///< NeighbourRefPos: where the lists were built
  const shared::uint* __restrict__ order;        ///< GridOrder
  const shared::uint* __restrict__ cell_start;   ///< GridCellStart
  const shared::uint* __restrict__ sbody;        ///< SortedBody
  const shared::ContactLaw* __restrict__ laws;   ///< ContactLaws
  const shared::PlaneData* __restrict__ planes;  ///< Planes
};

}  // namespace motes::cuda
