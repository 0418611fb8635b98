// The buffers a particle's contacts are found and evaluated from, gathered once for
// contacts_compute, impulses_compute and impulses_sweep.cpp: the particles' position, velocity,
// body and material, the neighbour lists, the grid of the last build (walked instead by a particle
// with more neighbours than its list holds), the contact laws and the planes.
#pragma once

#include "shared/params.h"

namespace motes::openmp {

struct ContactInputs {
  const shared::vec4* pos;          ///< ParticlePos
  const shared::vec4* vel;          ///< ParticleVel
  const shared::uint* body;         ///< ParticleBody
  const shared::uint* material;     ///< ParticleMaterial
  const shared::uint* list;         ///< NeighbourList: entry k of particle i at k * N + i
  const shared::uint* count;        ///< NeighbourCount
  const shared::vec4* ref;          ///< NeighbourRefPos: where the lists were built
  const shared::uint* order;        ///< GridOrder
  const shared::uint* cell_start;   ///< GridCellStart
  const shared::uint* sbody;        ///< SortedBody
  const shared::ContactLaw* laws;   ///< ContactLaws
  const shared::PlaneData* planes;  ///< Planes
};

}  // namespace motes::openmp
