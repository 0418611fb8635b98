// Generalized winding number with a bounding-volume hierarchy, and the mesh topology around it.
//
// w(q) = 1/(4 pi) sum_t Omega_t(q), Omega_t the signed solid angle of triangle t seen from q.
//
// Far field: seen from far away, a cluster of triangles with vector areas A_t (half the cross
// product, normal times area) at centroids x_t acts like a sum of dipoles. With c the cluster's
// area-weighted centre, y = c - q and f(y) = y / (4 pi |y|^3) the solid-angle kernel, the first
// two terms of the Taylor expansion of f around y give
//   w_cluster(q) ~ A . f(y) + sum_ij J_ij(y) M_ij,   A = sum_t A_t,  M_ij = sum_t A_t,i (x_t -
//   c)_j,
// where J = df/dy = (I / |y|^3 - 3 y y^T / |y|^5) / (4 pi). Both sums are exact integrals of the
// expansion over flat triangles (the integral of x over a triangle is its area times its
// centroid), so the error is the second-order remainder: relative to the cluster's own share it
// is of order (r / |y|)^2 for a cluster of radius r, used only where |y| > accuracy * r.
#include "winding_number.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <utility>

namespace motes::winding {

namespace {

constexpr double kInverseFourPi = 0.25 / std::numbers::pi;
// Triangles per leaf: a leaf is summed exactly when q is near it.
constexpr std::size_t kLeafSize = 8;

struct Node {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // area-weighted centroid
  double radius2 = 0.0;  // squared distance from the centre to its farthest vertex
  Eigen::Vector3d area = Eigen::Vector3d::Zero();    // sum of vector areas
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();  // M_ij = sum A_i (x - centre)_j
  std::uint32_t begin = 0, end = 0;                  // triangles [begin, end) in tree order
  std::uint32_t right = 0;                           // second child; 0: a leaf (first: next node)
};

}  // namespace

double solid_angle_fraction(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  // tan(Omega / 2) = numerator / denominator; atan2 picks the right half-turn.
  return 2.0 * std::atan2(numerator, denominator) * kInverseFourPi;
}

double curtain_fraction(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int side) {
  if (side == 0) return 0.0;
  // solid_angle_fraction(a, b, c) with the unit vector c = (0, 0, -1): the triple product is
  // a . (b x c) = -(a x b).z, of the sign given by `side`.
  const double la = a.norm(), lb = b.norm();
  const double numerator = std::abs(a.x() * b.y() - a.y() * b.x()) * (side > 0 ? -1.0 : 1.0);
  const double denominator = la * lb + a.dot(b) - a.z() * lb - b.z() * la;
  return 2.0 * std::atan2(numerator, denominator) * kInverseFourPi;
}

struct WindingNumber::Tree {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;  // in tree order
  std::vector<Node> nodes;

  // Per triangle (in the order being built): centroid and vector area.
  std::vector<Eigen::Vector3d> centroid;
  std::vector<Eigen::Vector3d> vector_area;
  std::vector<std::uint32_t> order;

  std::uint32_t build(std::uint32_t begin, std::uint32_t end) {
    const auto index = static_cast<std::uint32_t>(nodes.size());
    nodes.emplace_back();
    Node node;
    node.begin = begin;
    node.end = end;
    double total = 0.0;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero(), plain = Eigen::Vector3d::Zero();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t t = order[i];
      const double a = vector_area[t].norm();
      total += a;
      weighted += a * centroid[t];
      plain += centroid[t];
      node.area += vector_area[t];
      lo = lo.cwiseMin(centroid[t]);
      hi = hi.cwiseMax(centroid[t]);
    }
    node.centre = total > 0.0 ? Eigen::Vector3d(weighted / total)
                              : Eigen::Vector3d(plain / static_cast<double>(end - begin));
    double radius2 = 0.0;
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t t = order[i];
      node.spread += vector_area[t] * (centroid[t] - node.centre).transpose();
      for (int k = 0; k < 3; ++k) {
        radius2 = std::max(radius2, (vertices[triangles[t][k]] - node.centre).squaredNorm());
      }
    }
    node.radius2 = radius2;
    if (end - begin > kLeafSize) {
      // Split at the median centroid along the longest side of the centroids' box.
      Eigen::Index axis = 0;
      (hi - lo).maxCoeff(&axis);
      const std::uint32_t middle = begin + (end - begin) / 2;
      std::nth_element(
          order.begin() + begin, order.begin() + middle, order.begin() + end,
          [&](std::uint32_t p, std::uint32_t q) { return centroid[p][axis] < centroid[q][axis]; });
      build(begin, middle);
      node.right = build(middle, end);
    }
    nodes[index] = node;
    return index;
  }

  [[nodiscard]] double leaf_sum(const Node& node, const Eigen::Vector3d& q) const {
    double sum = 0.0;
    for (std::uint32_t i = node.begin; i < node.end; ++i) {
      const Eigen::Vector3i& t = triangles[i];
      sum += solid_angle_fraction(vertices[t[0]] - q, vertices[t[1]] - q, vertices[t[2]] - q);
    }
    return sum;
  }

  [[nodiscard]] double query(const Eigen::Vector3d& q, double accuracy2) const {
    double sum = 0.0;
    // Depth-first; the tree is balanced (median splits), so its depth is about log2(n / 8) and
    // the stack never holds more than depth + 1 nodes.
    std::array<std::uint32_t, 96> stack{};
    std::size_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes[stack[--top]];
      const Eigen::Vector3d y = node.centre - q;
      const double r2 = y.squaredNorm();
      if (r2 > accuracy2 * node.radius2) {
        const double inverse2 = 1.0 / r2;
        const double inverse3 = inverse2 * std::sqrt(inverse2);
        const double dipole = node.area.dot(y) * inverse3;
        const double gradient =
            (node.spread.trace() - 3.0 * y.dot(node.spread * y) * inverse2) * inverse3;
        sum += (dipole + gradient) * kInverseFourPi;
      } else if (node.right == 0) {
        sum += leaf_sum(node, q);
      } else {
        stack[top++] = node.right;
        stack[top++] = static_cast<std::uint32_t>(&node - nodes.data()) + 1;
      }
    }
    return sum;
  }
};

WindingNumber::WindingNumber(std::vector<Eigen::Vector3d> vertices,
                             std::vector<Eigen::Vector3i> triangles)
    : tree_(std::make_unique<Tree>()) {
  Tree& tree = *tree_;
  tree.vertices = std::move(vertices);
  tree.triangles = std::move(triangles);
  const std::size_t n = tree.triangles.size();
  tree.centroid.resize(n);
  tree.vector_area.resize(n);
  tree.order.resize(n);
  for (std::size_t t = 0; t < n; ++t) {
    const Eigen::Vector3d& a = tree.vertices[tree.triangles[t][0]];
    const Eigen::Vector3d& b = tree.vertices[tree.triangles[t][1]];
    const Eigen::Vector3d& c = tree.vertices[tree.triangles[t][2]];
    tree.centroid[t] = (a + b + c) / 3.0;
    tree.vector_area[t] = 0.5 * (b - a).cross(c - a);
  }
  std::iota(tree.order.begin(), tree.order.end(), 0U);
  if (n > 0) tree.build(0, static_cast<std::uint32_t>(n));
  std::vector<Eigen::Vector3i> sorted(n);
  for (std::size_t i = 0; i < n; ++i) sorted[i] = tree.triangles[tree.order[i]];
  tree.triangles = std::move(sorted);
  tree.centroid = {};
  tree.vector_area = {};
  tree.order = {};
}

WindingNumber::~WindingNumber() = default;
WindingNumber::WindingNumber(WindingNumber&&) noexcept = default;
WindingNumber& WindingNumber::operator=(WindingNumber&&) noexcept = default;

double WindingNumber::operator()(const Eigen::Vector3d& q, double accuracy) const {
  return tree_->nodes.empty() ? 0.0 : tree_->query(q, accuracy * accuracy);
}

double WindingNumber::exact(const Eigen::Vector3d& q) const {
  double sum = 0.0;
  for (const Eigen::Vector3i& t : tree_->triangles) {
    sum += solid_angle_fraction(tree_->vertices[t[0]] - q, tree_->vertices[t[1]] - q,
                                tree_->vertices[t[2]] - q);
  }
  return sum;
}

namespace {

/// One use of an undirected edge (lo, hi) by a triangle, in direction lo -> hi or back.
struct EdgeUse {
  int lo = 0, hi = 0;
  std::uint32_t triangle = 0;
  bool forward = false;

  bool operator<(const EdgeUse& o) const {
    if (lo != o.lo) return lo < o.lo;
    if (hi != o.hi) return hi < o.hi;
    return triangle < o.triangle;
  }
};

std::vector<EdgeUse> edge_uses(const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<EdgeUse> uses;
  uses.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int a = triangles[t][c];
      const int b = triangles[t][(c + 1) % 3];
      uses.push_back({std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(t), a < b});
    }
  }
  std::sort(uses.begin(), uses.end());
  return uses;
}

/// Calls f(first, last) for each run of uses of one undirected edge.
template <typename F>
void for_each_edge(const std::vector<EdgeUse>& uses, F f) {
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    f(i, j);
    i = j;
  }
}

}  // namespace

EdgeCounts count_edges(const std::vector<Eigen::Vector3i>& triangles) {
  EdgeCounts counts;
  const std::vector<EdgeUse> uses = edge_uses(triangles);
  for_each_edge(uses, [&](std::size_t first, std::size_t last) {
    if (last - first == 1) ++counts.open;
    if (last - first >= 3) ++counts.non_manifold;
  });
  return counts;
}

std::vector<BoundaryEdge> oriented_boundary(const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<BoundaryEdge> boundary;
  const std::vector<EdgeUse> uses = edge_uses(triangles);
  for_each_edge(uses, [&](std::size_t first, std::size_t last) {
    int net = 0;
    for (std::size_t i = first; i < last; ++i) net += uses[i].forward ? 1 : -1;
    if (net != 0) boundary.push_back({uses[first].lo, uses[first].hi, net});
  });
  return boundary;
}

Orientation orient_consistently(const std::vector<Eigen::Vector3d>& vertices,
                                std::vector<Eigen::Vector3i>& triangles) {
  Orientation result;
  const std::size_t n = triangles.size();
  // Neighbours across manifold edges, as a compressed list: (neighbour, same direction?).
  const std::vector<EdgeUse> uses = edge_uses(triangles);
  std::vector<std::uint32_t> degree(n + 1, 0);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for_each_edge(uses, [&](std::size_t first, std::size_t last) {
    if (last - first != 2 || uses[first].triangle == uses[first + 1].triangle) return;
    pairs.emplace_back(first, first + 1);
    ++degree[uses[first].triangle + 1];
    ++degree[uses[first + 1].triangle + 1];
  });
  std::partial_sum(degree.begin(), degree.end(), degree.begin());
  struct Link {
    std::uint32_t other = 0;
    bool same = false;  // both triangles run along the edge in the same direction
  };
  std::vector<Link> links(degree[n]);
  std::vector<std::uint32_t> fill(degree.begin(), degree.end() - 1);
  for (const auto& [p, q] : pairs) {
    const EdgeUse& u = uses[p];
    const EdgeUse& v = uses[q];
    const bool same = u.forward == v.forward;
    links[fill[u.triangle]++] = {v.triangle, same};
    links[fill[v.triangle]++] = {u.triangle, same};
  }

  auto area = [&](std::uint32_t t) {
    const Eigen::Vector3i& f = triangles[t];
    return (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]).norm();
  };
  constexpr std::int8_t kUnseen = -1;
  std::vector<std::int8_t> flip(n, kUnseen);
  std::vector<std::uint32_t> patch;
  for (std::uint32_t seed = 0; seed < n; ++seed) {
    if (flip[seed] != kUnseen) continue;
    patch.clear();
    patch.push_back(seed);
    flip[seed] = 0;
    for (std::size_t next = 0; next < patch.size(); ++next) {
      const std::uint32_t t = patch[next];
      for (std::uint32_t l = degree[t]; l < degree[t + 1]; ++l) {
        const Link& link = links[l];
        // Neighbours agree when they run along their shared edge in opposite directions.
        const auto want = static_cast<std::int8_t>(flip[t] ^ (link.same ? 1 : 0));
        if (flip[link.other] == kUnseen) {
          flip[link.other] = want;
          patch.push_back(link.other);
        } else if (flip[link.other] != want) {
          result.orientable = false;
        }
      }
    }
    double flipped = 0.0, kept = 0.0;
    for (const std::uint32_t t : patch) (flip[t] != 0 ? flipped : kept) += area(t);
    const bool invert = flipped > kept;
    for (const std::uint32_t t : patch) {
      if ((flip[t] != 0) != invert) {
        std::swap(triangles[t][1], triangles[t][2]);
        ++result.reversed;
      }
    }
  }
  return result;
}

}  // namespace motes::winding
