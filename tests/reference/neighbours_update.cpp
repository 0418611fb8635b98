// The oracle of neighbours_update (reference.h has the contract): grid_build then neighbours_build
// when the rebuild word asks for them, nothing otherwise.
#include "reference.h"
#include "shared/neighbours.h"

namespace motes_ref {

bool neighbours_update(const Particles& particles, const std::vector<uint>& state,
                       const StepParams& p, Grid& grid, Neighbours& nb) {
  if (state[MOTES_NEIGHBOUR_REBUILD] == 0u) return false;
  grid = grid_build(particles, p);
  nb = neighbours_build(particles, grid, p);
  return true;
}

}  // namespace motes_ref
