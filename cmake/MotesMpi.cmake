# MPI (Debian's OpenMPI: libopenmpi-dev, openmpi-bin): builds motes_mpi (mpi/, the distributed
# simulation of docs/scale-out.md) and lets `motes run` go over ranks under mpirun. Sets MOTES_MPI
# and MOTES_MPI_STATUS.
set(MOTES_MPI OFF)
set(MOTES_MPI_STATUS "off")
if(NOT MOTES_WITH_MPI STREQUAL "OFF")
  if(MOTES_WITH_MPI STREQUAL "ON")
    find_package(MPI REQUIRED COMPONENTS C)
  else()
    find_package(MPI QUIET COMPONENTS C)
  endif()
  if(MPI_C_FOUND)
    set(MOTES_MPI ON)
    set(MOTES_MPI_STATUS "MPI ${MPI_C_VERSION} (${MPIEXEC_EXECUTABLE})")
    add_subdirectory(mpi)
  else()
    set(MOTES_MPI_STATUS "not found (Debian: libopenmpi-dev openmpi-bin)")
  endif()
endif()
