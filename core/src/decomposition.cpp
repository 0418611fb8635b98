// Brick-grid domain decomposition (motes/decomposition.h).
#include "motes/decomposition.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace motes {

int Decomposition::owner(const Eigen::Vector3d& p) const {
  int index[3] = {0, 0, 0};
  for (int a = 0; a < 3; ++a) {
    const int n = cells[static_cast<std::size_t>(a)];
    const double extent = upper[a] - lower[a];
    if (n <= 1 || !(extent > 0.0)) continue;
    const double t = (p[a] - lower[a]) / extent * static_cast<double>(n);
    // !(t >= 0) also takes NaN to the lowest brick.
    index[a] = !(t >= 0.0) ? 0 : t >= static_cast<double>(n - 1) ? n - 1 : static_cast<int>(t);
  }
  return index[0] + cells[0] * (index[1] + cells[1] * index[2]);
}

std::string Decomposition::describe() const {
  return fmt::format("{} x {} x {}", cells[0], cells[1], cells[2]);
}

std::vector<Eigen::Vector3d> body_centres(const Scene& scene) {
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(scene.bodies.size() + scene.linked.size());
  for (const BodySpec& b : scene.bodies) centres.push_back(b.position);
  for (const LinkedSpec& l : scene.linked) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : l.points) sum += p;
    centres.push_back(l.points.empty() ? sum : sum / static_cast<double>(l.points.size()));
  }
  return centres;
}

Result<Decomposition> choose_decomposition(const std::vector<Eigen::Vector3d>& centres, int ranks,
                                           const std::optional<std::array<int, 3>>& forced) {
  if (ranks < 1) return Status::error(fmt::format("decomposition: {} ranks", ranks));
  Decomposition d;
  d.lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  d.upper = -d.lower;
  for (const Eigen::Vector3d& c : centres) {
    if (!c.allFinite()) continue;
    d.lower = d.lower.cwiseMin(c);
    d.upper = d.upper.cwiseMax(c);
  }
  if (!(d.lower.array() <= d.upper.array()).all()) {
    d.lower.setZero();
    d.upper.setZero();
  }
  if (forced) {
    const std::array<int, 3>& f = *forced;
    if (f[0] < 1 || f[1] < 1 || f[2] < 1 ||
        static_cast<long long>(f[0]) * f[1] * f[2] != static_cast<long long>(ranks)) {
      return Status::error(fmt::format(
          "--decomposition {},{},{}: the bricks along x, y and z must multiply to the {} ranks",
          f[0], f[1], f[2], ranks));
    }
    d.cells = f;
    return d;
  }
  // Every factorisation X Y Z = ranks; the cut area (X - 1) Ey Ez + ... is what the halos scale
  // with. A flat extent still counts a little, so that a 2D scene is not cut across its thin axis.
  const Eigen::Vector3d extent =
      (d.upper - d.lower).cwiseMax(1e-9 * (d.upper - d.lower).maxCoeff() + 1e-12);
  double best = std::numeric_limits<double>::infinity();
  for (int x = ranks; x >= 1; --x) {
    if (ranks % x != 0) continue;
    for (int y = ranks / x; y >= 1; --y) {
      if ((ranks / x) % y != 0) continue;
      const int z = ranks / x / y;
      const double area = (x - 1) * extent.y() * extent.z() + (y - 1) * extent.x() * extent.z() +
                          (z - 1) * extent.x() * extent.y();
      if (area < best * (1.0 - 1e-12)) {
        best = area;
        d.cells = {x, y, z};
      }
    }
  }
  return d;
}

Result<std::array<int, 3>> parse_decomposition(const std::string& text) {
  std::array<int, 3> cells{0, 0, 0};
  std::istringstream in(text);
  char comma1 = 0, comma2 = 0;
  long long v[3] = {0, 0, 0};
  in >> v[0] >> comma1 >> v[1] >> comma2 >> v[2];
  const bool whole = in && comma1 == ',' && comma2 == ',' && (in >> std::ws).eof();
  if (!whole || v[0] < 1 || v[1] < 1 || v[2] < 1 || v[0] > 1 << 20 || v[1] > 1 << 20 ||
      v[2] > 1 << 20) {
    return Status::error(fmt::format(
        "--decomposition '{}': expected X,Y,Z, three whole numbers >= 1 (bricks along x, y, z)",
        text));
  }
  for (int a = 0; a < 3; ++a) cells[static_cast<std::size_t>(a)] = static_cast<int>(v[a]);
  return cells;
}

}  // namespace motes
