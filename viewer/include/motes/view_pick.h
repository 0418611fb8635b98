// Picking a particle under the cursor (`motes view`'s grab, docs/viewer.md): the nearest sphere a
// ray meets, found through a uniform grid of the spheres built on the host, as a scan of every
// sphere would find it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "shared/common.h"

namespace motes::viewer {

/// How far along the ray from `origin` in direction `unit_dir` (unit length) it first meets sphere
/// `s` (xyz centre, w radius): the nearer root, or +infinity when the ray's line misses it. A ray
/// that starts inside the sphere gets a negative distance: a pick takes only positive ones.
float ray_sphere(const Eigen::Vector3f& origin, const Eigen::Vector3f& unit_dir,
                 const shared::vec4& s);

/// What a pick found: the particle with the nearest hit in front of the origin (ray_sphere; the
/// lower index of equal ones), where: origin + t dir, and how many sphere tests it made.
struct PickHit {
  bool hit = false;
  std::uint32_t particle = 0;
  float t = 0.0f;
  std::size_t tests = 0;
};

/// Which particles may be picked (false: skipped, as if absent).
using Pickable = std::function<bool(std::uint32_t)>;

/// The reference: every sphere tested.
PickHit pick_every_sphere(std::span<const shared::vec4> spheres, const Pickable& pickable,
                          const Eigen::Vector3f& origin, const Eigen::Vector3f& dir);

/// The pickable spheres binned by centre into a uniform grid of cubic cells at least twice the
/// largest radius wide (wider when the spheres are spread thin, so that the cells are not many
/// more than the spheres), sorted by cell (a counting sort: building is O(N)). A ray walks the
/// cells it crosses front to back (Amanatides & Woo) and tests the spheres binned in each cell's
/// 3 x 3 x 3 neighbourhood (a sphere reaches at most one cell beyond its own, so a point of it
/// lies in a cell next to its centre's); it stops once the nearest hit so far is nearer than the
/// cell it leaves: a sphere not yet tested starts at least half a cell beyond. Particles with a
/// position or radius that is not finite are left out (the scan never picks them either).
class PickGrid {
 public:
  PickGrid() = default;
  PickGrid(std::span<const shared::vec4> spheres, const Pickable& pickable);

  /// The same particle and t as pick_every_sphere over the spheres it was built from.
  [[nodiscard]] PickHit pick(const Eigen::Vector3f& origin, const Eigen::Vector3f& ray) const;

  [[nodiscard]] float cell_size() const { return cell_; }
  /// The lowest corner of cell (0, 0, 0): the least coordinates of the binned centres.
  [[nodiscard]] const Eigen::Vector3f& corner() const { return lo_; }
  [[nodiscard]] std::array<int, 3> cells() const { return {n_[0], n_[1], n_[2]}; }

 private:
  std::vector<shared::vec4> spheres_;             ///< the binned ones, in cell order
  std::vector<std::uint32_t> index_;              ///< their particle numbers
  std::vector<std::uint32_t> start_;              ///< cell c's spheres: [start_[c], start_[c + 1])
  Eigen::Vector3f lo_ = Eigen::Vector3f::Zero();  ///< the corner of cell (0, 0, 0)
  float cell_ = 1.0f;
  float inv_cell_ = 1.0f;
  int n_[3] = {0, 0, 0};
};

}  // namespace motes::viewer
