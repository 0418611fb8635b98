#include "mpi_support.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "motes/devices.h"
#include "motes/workloads.h"

namespace motes::mpi_test {

std::string backend() {
  const char* b = std::getenv("MOTES_MPI_BACKEND");
  return b != nullptr && *b != '\0' ? b : "openmp";
}

DeviceOpener opener() {
  return [] {
    DeviceOptions options;
    options.cpu_threads = 1;
    return open_device(backend(), -1, options);
  };
}

int rank_in(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}

int size_of(MPI_Comm comm) {
  int n = 1;
  MPI_Comm_size(comm, &n);
  return n;
}

Scene shaken_settle(double stiffness_factor) {
  Scene scene = settle_workload(12, 6, 12);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> speed(-2.0, 2.0);
  for (BodySpec& b : scene.bodies) b.velocity = {speed(random), speed(random), speed(random)};
  for (Material& m : scene.materials) m.stiffness *= stiffness_factor;
  return scene;
}

Scene example(const std::string& name) {
  // Appended rather than `a + b + c`: GCC 12 warns falsely (-Warray-bounds) inside
  // std::string's operator+ on the temporaries here.
  std::string path = MOTES_SOURCE_DIR "/examples/scenes/";
  path.append(name).append(".json");
  Result<Scene> scene = load_scene_file(path);
  EXPECT_TRUE(scene) << scene.message();
  return scene ? scene.value() : Scene{};
}

}  // namespace motes::mpi_test
