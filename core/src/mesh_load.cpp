// Triangle meshes from files (through assimp) and their closedness check.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numeric>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "motes/shapes.h"

namespace motes {
namespace {

bool position_less(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  if (a.x() != b.x()) return a.x() < b.x();
  if (a.y() != b.y()) return a.y() < b.y();
  return a.z() < b.z();
}

/// Makes vertices at identical positions one vertex, in order of first use. assimp only joins
/// vertices whose normals and texture coordinates agree too, and STL stores every triangle's
/// corners separately, so without this a closed STL mesh would look like a soup of open triangles.
void merge_coincident_vertices(TriangleMesh& mesh) {
  const auto n = mesh.vertices.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0U);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return position_less(mesh.vertices[a], mesh.vertices[b]);
  });
  // group[v] = first vertex (in file order) at the same position as v.
  std::vector<std::uint32_t> group(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j < n && mesh.vertices[order[j]] == mesh.vertices[order[i]])
      group[order[j++]] = order[i];
    i = j;
  }
  constexpr auto kUnset = static_cast<std::uint32_t>(-1);
  std::vector<std::uint32_t> new_index(n, kUnset);
  std::vector<Eigen::Vector3d> merged;
  for (std::size_t v = 0; v < n; ++v) {
    if (group[v] == v) {
      new_index[v] = static_cast<std::uint32_t>(merged.size());
      merged.push_back(mesh.vertices[v]);
    }
  }
  std::vector<Eigen::Vector3i> kept;
  kept.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    Eigen::Vector3i m;
    for (int c = 0; c < 3; ++c) m[c] = static_cast<int>(new_index[group[t[c]]]);
    // A triangle with two corners at one position has no area and would be counted as using
    // an edge from a vertex to itself: it adds nothing to the surface, so it is dropped.
    if (m[0] == m[1] || m[1] == m[2] || m[2] == m[0]) continue;
    kept.push_back(m);
  }
  mesh.vertices = std::move(merged);
  mesh.triangles = std::move(kept);
}

}  // namespace

Result<TriangleMesh> load_mesh(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) {
    return Status::error(fmt::format("{}: cannot open mesh file: no such file", path));
  }
  if (std::filesystem::is_directory(status)) {
    return Status::error(fmt::format("{}: is a directory, not a mesh file", path));
  }

  Assimp::Importer importer;
  // Points and lines (which Triangulate leaves alone) are removed: only surfaces enclose volume.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // The file is read and validated first (aiProcess_ValidateDataStructure, alone): assimp's
  // post-processing steps trust the structure an importer built, and a malformed file (an OFF
  // with faces but no indices, found by fuzzing: docs/fuzzing.md) crashes them. A file with no
  // mesh at all fails validation too; it gets our own message below, not aiScene's internals.
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  if (scene == nullptr) {
    const std::string why = importer.GetErrorString();
    if (why.find("mNumMeshes") != std::string::npos || why.find("no meshes") != std::string::npos) {
      return Status::error(fmt::format(
          "{}: the file contains no triangles (points, lines and faces without area do not "
          "count): it encloses no volume",
          path));
    }
    return Status::error(fmt::format("{}: cannot read mesh: {}", path, why));
  }
  // PreTransformVertices applies the node transforms of formats that have a scene graph, so the
  // particles come out where the file places the mesh; the indices are range-checked below too.
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_SortByPType | aiProcess_PreTransformVertices;
  scene = importer.ApplyPostProcessing(flags);
  if (scene == nullptr) {
    return Status::error(fmt::format("{}: cannot read mesh: {}", path, importer.GetErrorString()));
  }

  TriangleMesh mesh;
  mesh.source = path;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* part = scene->mMeshes[m];
    if (part == nullptr || part->mVertices == nullptr) continue;
    const auto base = mesh.vertices.size();
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      const aiVector3D& p = part->mVertices[v];
      // + 0.0 turns -0.0 into +0.0 so that both merge as one position.
      Eigen::Vector3d q(static_cast<double>(p.x) + 0.0, static_cast<double>(p.y) + 0.0,
                        static_cast<double>(p.z) + 0.0);
      if (!q.allFinite()) {
        return Status::error(
            fmt::format("{}: vertex {} of mesh {} has a non-finite coordinate ({}, {}, {})", path,
                        v, m, q.x(), q.y(), q.z()));
      }
      mesh.vertices.push_back(q);
    }
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned c = 0; c < 3; ++c) {
        if (face.mIndices[c] >= part->mNumVertices) {
          return Status::error(
              fmt::format("{}: face {} of mesh {} uses vertex {}, but the mesh has {} vertices",
                          path, f, m, face.mIndices[c], part->mNumVertices));
        }
      }
      mesh.triangles.emplace_back(static_cast<int>(base + face.mIndices[0]),
                                  static_cast<int>(base + face.mIndices[1]),
                                  static_cast<int>(base + face.mIndices[2]));
    }
  }
  merge_coincident_vertices(mesh);
  if (mesh.triangles.empty()) {
    return Status::error(fmt::format(
        "{}: the file contains no triangles (points, lines and faces without area do not count): "
        "nothing to fill with particles",
        path));
  }
  return mesh;
}

std::size_t count_open_edges(const TriangleMesh& mesh) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (int c = 0; c < 3; ++c) {
      const int a = t[c];
      const int b = t[(c + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::size_t open = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) ++open;
    i = j;
  }
  return open;
}

}  // namespace motes
