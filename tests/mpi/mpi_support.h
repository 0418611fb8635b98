// What the MPI tests share: the backend they run on, the device each rank opens, and the scenes
// that more than one of them runs.
#pragma once

#include <mpi.h>

#include <string>

#include "motes/distributed.h"
#include "motes/scene.h"

namespace motes::mpi_test {

/// MOTES_MPI_BACKEND, or openmp.
std::string backend();

/// Opens backend() with one CPU thread (each rank is one process).
DeviceOpener opener();

/// This process's rank in `comm`, and the number of ranks.
int rank_in(MPI_Comm comm);
int size_of(MPI_Comm comm);

/// W1's spheres given random velocities (up to 2 m/s a component, seeded), the materials'
/// stiffness multiplied by `stiffness_factor`: they collide with each other, the walls and the
/// floor within a few hundred steps, across every rank boundary, with many partitions and
/// migrations.
Scene shaken_settle(double stiffness_factor = 1.0);

/// examples/scenes/NAME.json (a failed expectation when it does not load).
Scene example(const std::string& name);

}  // namespace motes::mpi_test
