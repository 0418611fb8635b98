// neighbours_update: grid_build and neighbours_build when a rebuild is due (NeighbourState),
// nothing otherwise.
#include <chrono>

#include "openmp_device.h"
#include "shared/neighbours.h"

namespace motes::openmp {

void OpenMPDevice::neighbours_update(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const bool rebuild = buf<shared::uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] != 0;
  record(Kernel::NeighboursUpdate, start);
  if (!rebuild) return;
  grid_build(p);
  neighbours_build(p);
}

}  // namespace motes::openmp
