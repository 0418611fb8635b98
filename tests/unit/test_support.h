// Helpers shared by the unit tests: temporary directories and a closed box mesh.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <system_error>

#include "motes/shapes.h"

namespace motes_test {

/// A fresh directory under the system's temporary folder, named after the running test and
/// removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("motes_" + std::string(info->test_suite_name()) + "_" + std::string(info->name()) +
             "_" + std::to_string(::getpid()));
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

}  // namespace motes_test
