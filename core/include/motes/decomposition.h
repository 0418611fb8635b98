// Spatial domain decomposition for runs over several MPI ranks (docs/scale-out.md): a brick grid
// of X x Y x Z cells over the scene's bounds, one rank per cell. No MPI here: what rank owns a
// point is plain geometry, the same on every rank.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>

#include "motes/api.h"
#include "motes/scene.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

struct Decomposition {
  std::array<int, 3> cells{1, 1, 1};  ///< bricks along x, y, z; their product is the rank count
  Eigen::Vector3d lower = Eigen::Vector3d::Zero();  ///< the bricks split [lower, upper]
  Eigen::Vector3d upper = Eigen::Vector3d::Zero();

  [[nodiscard]] int ranks() const { return cells[0] * cells[1] * cells[2]; }
  /// The rank whose brick holds `p` (rank = i + X (j + Y k)). The outer bricks reach to
  /// infinity, so every point, also one that has left the start bounds, has exactly one owner;
  /// a NaN coordinate counts as the lowest brick.
  [[nodiscard]] int owner(const Eigen::Vector3d& p) const;
  /// "X x Y x Z" for messages.
  [[nodiscard]] std::string describe() const;
};

/// The centre of every scene body (BodySpec::position; a cloth's or rope's mean point) in the
/// scene's body order, bodies then cloths and ropes: the points that decide ownership at the
/// start.
std::vector<Eigen::Vector3d> body_centres(const Scene& scene);

/// The decomposition for `ranks` ranks over the bounds of `centres`: `forced` (X, Y, Z) when
/// given (an error unless X Y Z = ranks, each >= 1), otherwise the brick grid whose cut faces
/// have the least total area (slabs across the longest extent when that is best; of equal
/// areas, the one with more cuts along x, then y).
Result<Decomposition> choose_decomposition(const std::vector<Eigen::Vector3d>& centres, int ranks,
                                           const std::optional<std::array<int, 3>>& forced = {});

/// Parses "X,Y,Z" (--decomposition): three whole numbers >= 1.
Result<std::array<int, 3>> parse_decomposition(const std::string& text);

}  // namespace motes
MOTES_API_END
