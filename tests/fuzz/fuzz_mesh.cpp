// Fuzz target: mesh file bytes -> motes::load_mesh (assimp) -> count_open_edges and voxelize
// (docs/fuzzing.md). The first byte picks what the rest is (modulo 5): a file for assimp with the
// extension that picks its importer, 0 .obj, 1 .ply, 2 .stl, 3 .off; or 4, a mesh built here
// without assimp (raw_mesh: small integer coordinates, so that the voxelizer's rays run through
// vertices and along edges, and many more runs per second: assimp spends 16 MB on every OBJ file).
// A mesh that loads is voxelized with few particles, so that each run stays fast: on a lattice of 8
// cells across its largest extent, and to a target count of 50 (the bisection on the diameter: a
// dozen to 35 fills of up to 50,000 cells) when it is closed or has at most kMaxCountTriangles
// triangles. A soup of 512 triangles with hundreds of open edges, whose winding number the
// hierarchy sums cell by cell, takes that bisection 0.5 s in a release build and 12 s under the
// sanitizers and libFuzzer's coverage, over its slow-input limit.
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "fuzz_targets.h"
#include "motes/shapes.h"

namespace motes::fuzz {

namespace {

/// What the scene loader relies on in a voxelized set.
void check_particles(const Result<ParticleSet>& set) {
  if (!set) {
    if (set.message().empty()) broken("mesh", "an error without a message");
    return;
  }
  if (set->points.empty()) broken("mesh", "voxelize returned no particles without an error");
  if (!(set->diameter > 0.0) || !std::isfinite(set->diameter)) broken("mesh", "a bad diameter");
  for (const Eigen::Vector3f& p : set->points) {
    if (!p.allFinite()) broken("mesh", "a particle that is not finite");
  }
}

/// Byte n: 1 + n % 32 vertices; then per vertex three signed bytes (its coordinates); then per
/// triangle three bytes (vertex indices, modulo the vertex count), until the bytes run out or
/// there are kMaxRawTriangles: enough for every kind of surface the voxelizer tells apart (open,
/// non-manifold, duplicated, flipped, overlapping, degenerate); more only slows each run.
constexpr std::size_t kMaxRawTriangles = 512;
constexpr std::size_t kMaxCountTriangles = 128;

TriangleMesh raw_mesh(const std::uint8_t* data, std::size_t size) {
  TriangleMesh mesh;
  mesh.source = "raw mesh";
  if (size == 0) return mesh;
  const std::size_t vertices = 1 + data[0] % 32;
  std::size_t at = 1;
  for (std::size_t v = 0; v < vertices && at + 3 <= size; ++v, at += 3) {
    mesh.vertices.emplace_back(static_cast<std::int8_t>(data[at]),
                               static_cast<std::int8_t>(data[at + 1]),
                               static_cast<std::int8_t>(data[at + 2]));
  }
  if (mesh.vertices.empty()) return mesh;
  const auto n = static_cast<unsigned>(mesh.vertices.size());
  for (; at + 3 <= size && mesh.triangles.size() < kMaxRawTriangles; at += 3) {
    mesh.triangles.emplace_back(data[at] % n, data[at + 1] % n, data[at + 2] % n);
  }
  return mesh;
}

}  // namespace

int mesh(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static constexpr std::array<const char*, 4> kExtensions = {".obj", ".ply", ".stl", ".off"};
  const std::size_t kind = data[0] % (kExtensions.size() + 1);
  Result<TriangleMesh> loaded = Status::error("not loaded");
  if (kind == kExtensions.size()) {
    loaded = raw_mesh(data + 1, size - 1);
  } else {
    const std::filesystem::path path = work_dir() / (std::string("mesh") + kExtensions[kind]);
    write_file(path, data + 1, size - 1);
    loaded = load_mesh(path.string());
    if (!loaded) {
      if (loaded.message().empty()) broken("mesh", "an error without a message");
      return 0;
    }
    if (loaded->triangles.empty()) broken("mesh", "load_mesh returned a mesh without triangles");
  }
  const TriangleMesh& mesh = loaded.value();
  const auto vertices = static_cast<int>(mesh.vertices.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int c = 0; c < 3; ++c) {
      if (t[c] < 0 || t[c] >= vertices) broken("mesh", "a triangle's vertex index is out of range");
      const Eigen::Vector3d& v = mesh.vertices[static_cast<std::size_t>(t[c])];
      if (!v.allFinite()) broken("mesh", "a vertex that is not finite");
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
  }
  const std::size_t open_edges = count_open_edges(mesh);

  if (open_edges == 0 || mesh.triangles.size() <= kMaxCountTriangles) {
    VoxelizeOptions by_count;
    by_count.target_count = 50;
    check_particles(voxelize(mesh, by_count));
  }
  VoxelizeOptions by_diameter;
  by_diameter.diameter = (hi - lo).maxCoeff() / 8.0;
  if (by_diameter.diameter > 0.0 && std::isfinite(by_diameter.diameter)) {
    check_particles(voxelize(mesh, by_diameter));
  }
  return 0;
}

}  // namespace motes::fuzz

#ifndef MOTES_FUZZ_REPLAY
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return motes::fuzz::mesh(data, size);
}
#endif
