// Helpers shared by the unit tests: temporary directories, a closed box mesh, grid triangles, and
// simulations of scene text on the backends CI has.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/shapes.h"
#include "motes/simulation.h"

namespace motes_test {

/// A fresh directory under the system's temporary folder, named after the running test and
/// removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    // One folder, not nested ones: a parameterized test's names hold '/' (Backends/Suite,
    // Case/openmp), whose parent folders removing the leaf would leave behind.
    std::string name = "motes_" + std::string(info->test_suite_name()) + "_" +
                       std::string(info->name()) + "_" + std::to_string(::getpid());
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::string operator/(const std::string& name) const {
    return (path_ / name).string();
  }

 private:
  std::filesystem::path path_;
};

/// A closed box mesh of the given size, rotated and then moved by `offset`.
inline motes::TriangleMesh box_mesh(const Eigen::Vector3d& size, const Eigen::Matrix3d& rotation,
                                    const Eigen::Vector3d& offset) {
  motes::TriangleMesh mesh;
  mesh.source = "box mesh";
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1) != 0 ? 0.5 : -0.5, (k & 2) != 0 ? 0.5 : -0.5,
                                 (k & 4) != 0 ? 0.5 : -0.5);
    mesh.vertices.push_back(rotation * corner.cwiseProduct(size) + offset);
  }
  // Corner k has bit 0 = +x, bit 1 = +y, bit 2 = +z; quads counter-clockwise from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

/// Adds the triangles of an along x across grid of vertices (vertex (i, k) is k * along + i) to
/// `m`, each square cut along alternating diagonals.
inline void add_grid_triangles(motes::TriangleMesh& m, int along, int across) {
  const auto at = [&](int i, int k) { return k * along + i; };
  for (int k = 0; k + 1 < across; ++k) {
    for (int i = 0; i + 1 < along; ++i) {
      if ((i + k) % 2 == 0) {
        m.triangles.emplace_back(at(i, k), at(i + 1, k), at(i + 1, k + 1));
        m.triangles.emplace_back(at(i, k), at(i + 1, k + 1), at(i, k + 1));
      } else {
        m.triangles.emplace_back(at(i, k), at(i + 1, k), at(i, k + 1));
        m.triangles.emplace_back(at(i + 1, k), at(i + 1, k + 1), at(i, k + 1));
      }
    }
  }
}

/// Whether `backend` has a device here; `why` says why not.
inline bool has_device(const std::string& backend, std::string& why) {
  for (const motes::BackendReport& r : motes::list_backends()) {
    if (r.backend != backend) continue;
    why = r.unavailable_reason;
    return !r.devices.empty();
  }
  why = "unknown backend";
  return false;
}

/// OpenMP, and Vulkan where it is built (CI: lavapipe); CUDA has tests of its own, which say when
/// they are skipped.
inline std::vector<std::string> cpu_backends() {
  std::vector<std::string> out = {"openmp"};
  if (motes::open_device("vulkan")) out.emplace_back("vulkan");
  return out;
}

/// A simulation of scene `text` (named `source`, meshes relative to `base_dir`) on `backend`;
/// null, with a failure recorded, when the scene, the device or the simulation cannot be made.
inline std::unique_ptr<motes::Simulation> simulate_text(const std::string& text,
                                                        const std::string& source,
                                                        const std::string& base_dir,
                                                        const std::string& backend) {
  motes::Result<motes::Scene> scene = motes::load_scene_text(text, source, base_dir);
  EXPECT_TRUE(scene) << scene.message();
  if (!scene) return nullptr;
  auto device = motes::open_device(backend);
  EXPECT_TRUE(device) << device.message();
  if (!device) return nullptr;
  auto sim = motes::Simulation::create(*scene, std::move(device.value()));
  EXPECT_TRUE(sim) << sim.message();
  return sim ? std::move(sim.value()) : nullptr;
}

/// Runs `steps` steps of `s` (kernel timing on when `timed`: CUDA then launches its calls one by
/// one), requires every particle's position finite and puts the state hash in `hash`; for tests
/// that compare two ways of stepping to the bit (ASSERT_NO_FATAL_FAILURE around it).
inline void step_and_hash(motes::Simulation& s, std::uint64_t steps, bool timed,
                          std::uint64_t& hash) {
  s.device().set_timing(timed);
  ASSERT_TRUE(s.step(steps));
  auto snapshot = s.snapshot();
  ASSERT_TRUE(snapshot) << snapshot.message();
  for (const motes::shared::vec4& x : snapshot.value().particle_pos) {
    ASSERT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z));
  }
  auto h = s.state_hash();
  ASSERT_TRUE(h) << h.message();
  hash = h.value();
}

/// Files the tests read: tests/data/meshes/NAME, the Stanford bunny, examples/scenes/NAME, and
/// the checkpoint tests' scene with every kind of state. (Appended rather than `a + b + c`: GCC
/// 12 warns falsely, -Warray-bounds, inside std::string's operator+ on such temporaries.)
inline std::string mesh_path(const std::string& name) {
  std::string path = MOTES_TEST_DATA_DIR "/meshes/";
  return path.append(name);
}
inline std::string bunny_path() { return MOTES_SOURCE_DIR "/examples/assets/bunny.obj"; }
inline std::string example_path(const std::string& name) {
  std::string path = MOTES_SOURCE_DIR "/examples/scenes/";
  return path.append(name);
}
inline const std::string kMixedScene = MOTES_TEST_DATA_DIR "/checkpoint/mixed.json";

/// A particle set's centres, sorted: two sets compared as sets.
inline std::vector<std::tuple<float, float, float>> sorted_points(const motes::ParticleSet& set) {
  std::vector<std::tuple<float, float, float>> out;
  for (const auto& p : set.points) out.emplace_back(p.x(), p.y(), p.z());
  std::sort(out.begin(), out.end());
  return out;
}

inline constexpr double kPi = std::numbers::pi;

/// Largest stable substep of semi-implicit Euler for x'' = -w0^2 x - gamma x' (w0^2 h^2 +
/// 2 gamma h < 4) with w0^2 = k / m_eff, written out here independently of the loader.
inline double stable_substep(double k, double gamma, double m_eff) {
  const double w2 = k / m_eff;
  return (-gamma + std::sqrt(gamma * gamma + 4 * w2)) / w2;
}

}  // namespace motes_test
