// Cloth and ropes: lattices of particles joined by distance constraints, and the colouring that
// lets each colour of constraints be relaxed in parallel (motes/cloth.h).
#include "motes/cloth.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>

namespace motes {

namespace {

Status check_common(const char* what, double diameter, double stiffness, double bend_stiffness) {
  if (!(diameter > 0.0) || !std::isfinite(diameter)) {
    return Status::error(fmt::format("{}: diameter must be > 0 (got {})", what, diameter));
  }
  for (const double s : {stiffness, bend_stiffness}) {
    if (!(s > 0.0 && s <= 1.0)) {
      return Status::error(fmt::format("{}: stiffness must be in (0, 1] (got {})", what, s));
    }
  }
  return Status::ok();
}

Status check_side(const char* what, const char* name, int count, int least) {
  if (count < least || static_cast<std::uint32_t>(count) > kLinkedMaxSide) {
    return Status::error(fmt::format("{}: {} must be from {} to {} (got {})", what, name, least,
                                     kLinkedMaxSide, count));
  }
  return Status::ok();
}

}  // namespace

double linked_particle_mass(double density, double diameter) {
  return density * std::numbers::pi / 6.0 * diameter * diameter * diameter;
}

Result<LinkedSpec> make_rope(const RopeOptions& o) {
  if (Status s = check_common("rope", o.diameter, o.stiffness, o.bend_stiffness); !s) return s;
  if (Status s = check_side("rope", "the particle count", o.count, 2); !s) return s;
  const std::vector<Eigen::Vector3d> path =
      o.path.empty() ? std::vector<Eigen::Vector3d>{o.from, o.to} : o.path;
  if (path.size() < 2) return Status::error("rope: a path needs at least two points");
  std::vector<double> arc = {0.0};  // arc length at each path point
  for (std::size_t k = 0; k < path.size(); ++k) {
    if (!path[k].allFinite()) return Status::error(fmt::format("rope: point {} is not finite", k));
    if (k > 0) arc.push_back(arc.back() + (path[k] - path[k - 1]).norm());
  }
  if (!(arc.back() > 0.0)) return Status::error("rope: its ends must be apart (length 0)");
  LinkedSpec r;
  r.kind = LinkedKind::Rope;
  r.diameter = o.diameter;
  const auto n = static_cast<std::uint32_t>(o.count);
  std::size_t seg = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double s = arc.back() * static_cast<double>(i) / static_cast<double>(n - 1);
    while (seg + 2 < path.size() && arc[seg + 1] < s) ++seg;
    const double len = arc[seg + 1] - arc[seg];
    const double t = len > 0.0 ? std::clamp((s - arc[seg]) / len, 0.0, 1.0) : 0.0;
    r.points.push_back(i + 1 == n ? path.back() : path[seg] + (path[seg + 1] - path[seg]) * t);
    r.lattice.push_back({i, 0u});
  }
  for (std::uint32_t i = 0; i + 1 < n; ++i) r.links.push_back({i, i + 1, o.stiffness});
  if (o.bend) {
    for (std::uint32_t i = 0; i + 2 < n; ++i) r.links.push_back({i, i + 2, o.bend_stiffness});
  }
  return r;
}

Result<LinkedSpec> make_cloth(const ClothOptions& o) {
  if (Status s = check_common("cloth", o.diameter, o.stiffness, o.bend_stiffness); !s) return s;
  if (Status s = check_side("cloth", "the particle count along u", o.nu, 2); !s) return s;
  if (Status s = check_side("cloth", "the particle count along v", o.nv, 2); !s) return s;
  if (!o.corner.allFinite() || !o.edge_u.allFinite() || !o.edge_v.allFinite() ||
      o.edge_u.cross(o.edge_v).norm() <= 1e-12 * o.edge_u.norm() * o.edge_v.norm() ||
      o.edge_u.norm() == 0.0) {
    return Status::error("cloth: its edges must be finite, non-zero and not parallel");
  }
  LinkedSpec c;
  c.kind = LinkedKind::Cloth;
  c.diameter = o.diameter;
  for (int j = 0; j < o.nv; ++j) {
    for (int i = 0; i < o.nu; ++i) {
      c.points.push_back(o.corner + o.edge_u * (static_cast<double>(i) / (o.nu - 1)) +
                         o.edge_v * (static_cast<double>(j) / (o.nv - 1)));
      c.lattice.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j)});
    }
  }
  const auto at = [&](int i, int j) { return cloth_index(o, i, j); };
  for (int j = 0; j < o.nv; ++j) {  // structural
    for (int i = 0; i < o.nu; ++i) {
      if (i + 1 < o.nu) c.links.push_back({at(i, j), at(i + 1, j), o.stiffness});
      if (j + 1 < o.nv) c.links.push_back({at(i, j), at(i, j + 1), o.stiffness});
    }
  }
  for (int j = 0; j + 1 < o.nv; ++j) {  // shear
    for (int i = 0; i + 1 < o.nu; ++i) {
      c.links.push_back({at(i, j), at(i + 1, j + 1), o.stiffness});
      c.links.push_back({at(i + 1, j), at(i, j + 1), o.stiffness});
    }
  }
  if (o.bend) {
    for (int j = 0; j < o.nv; ++j) {
      for (int i = 0; i < o.nu; ++i) {
        if (i + 2 < o.nu) c.links.push_back({at(i, j), at(i + 2, j), o.bend_stiffness});
        if (j + 2 < o.nv) c.links.push_back({at(i, j), at(i, j + 2), o.bend_stiffness});
      }
    }
  }
  return c;
}

Result<LinkedSpec> make_mesh_cloth(const TriangleMesh& mesh, const MeshClothOptions& o) {
  if (Status s = check_common("cloth", o.diameter, o.stiffness, o.bend_stiffness); !s) return s;
  if (mesh.triangles.empty()) {
    return Status::error(fmt::format("{}: the mesh has no triangles", mesh.source));
  }
  // Particles at the vertices the triangles use, in the order of their first use.
  constexpr std::uint32_t kUnused = ~0u;
  std::vector<std::uint32_t> point_of(mesh.vertices.size(), kUnused);
  LinkedSpec c;
  c.kind = LinkedKind::Cloth;
  c.diameter = o.diameter;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    std::array<std::uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(t[k]);
      if (t[k] < 0 || v >= mesh.vertices.size()) {
        return Status::error(fmt::format("{}: a triangle uses vertex {} of {}", mesh.source, t[k],
                                         mesh.vertices.size()));
      }
      if (point_of[v] == kUnused) {
        if (!mesh.vertices[v].allFinite()) {
          return Status::error(fmt::format("{}: vertex {} is not finite", mesh.source, v));
        }
        point_of[v] = static_cast<std::uint32_t>(c.points.size());
        c.points.push_back(mesh.vertices[v]);
      }
      tri[static_cast<std::size_t>(k)] = point_of[v];
    }
    if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2]) triangles.push_back(tri);
  }
  if (c.points.size() > kLinkedMaxMeshPoints) {
    return Status::error(fmt::format("{}: {} vertices; a cloth from a mesh has at most {}",
                                     mesh.source, c.points.size(), kLinkedMaxMeshPoints));
  }
  // Each edge once, with the vertices opposite it (at most two are used for a bend link).
  struct Edge {
    std::uint32_t opposite[2] = {0, 0};
    int triangles = 0;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, Edge> edges;
  for (const auto& t : triangles) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      Edge& e = edges[{std::min(a, b), std::max(a, b)}];
      if (e.triangles < 2) e.opposite[e.triangles] = t[(k + 2) % 3];
      ++e.triangles;
    }
  }
  std::set<std::pair<std::uint32_t, std::uint32_t>> linked;
  for (const auto& [ab, e] : edges) {
    linked.insert(ab);
    c.links.push_back({ab.first, ab.second, o.stiffness});
  }
  if (o.bend) {
    for (const auto& [ab, e] : edges) {
      if (e.triangles != 2) continue;  // a boundary edge, or one of a non-manifold fan
      const std::uint32_t a = std::min(e.opposite[0], e.opposite[1]);
      const std::uint32_t b = std::max(e.opposite[0], e.opposite[1]);
      if (a != b && linked.insert({a, b}).second) c.links.push_back({a, b, o.bend_stiffness});
    }
  }
  // The pairs within two links (which never touch) are listed per particle: at most the sum of
  // the squared link counts. A fan (one vertex in many triangles) would make that quadratic.
  std::vector<std::uint64_t> degree(c.points.size(), 0);
  for (const LinkSpec& l : c.links) {
    ++degree[l.a];
    ++degree[l.b];
  }
  std::uint64_t reach = 0;
  for (const std::uint64_t d : degree) reach += d * d;
  if (reach > kMaxNearPerPoint * c.points.size()) {
    const auto most =
        static_cast<std::size_t>(std::max_element(degree.begin(), degree.end()) - degree.begin());
    const Eigen::Vector3d& x = c.points[most];
    return Status::error(fmt::format(
        "{}: the vertex at [{}, {}, {}] has {} links (a fan of triangles): the particle pairs "
        "within two links, which motes lists so that they never touch, would number up to {}, "
        "over {} per particle; use a mesh whose vertices each join a few triangles",
        mesh.source, x.x(), x.y(), x.z(), degree[most], reach, kMaxNearPerPoint));
  }
  return c;
}

LinkNeighbourhoods link_neighbourhoods(const std::vector<LinkSpec>& links, std::uint32_t count) {
  std::vector<std::vector<std::uint32_t>> next(count);
  for (const LinkSpec& l : links) {
    next[l.a].push_back(l.b);
    next[l.b].push_back(l.a);
  }
  LinkNeighbourhoods out;
  out.start.push_back(0);
  std::vector<std::uint32_t> near;
  for (std::uint32_t k = 0; k < count; ++k) {
    near.clear();
    for (const std::uint32_t a : next[k]) {
      near.push_back(a);
      for (const std::uint32_t b : next[a]) near.push_back(b);
    }
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    for (const std::uint32_t a : near) {
      if (a != k) out.list.push_back(a);
    }
    out.start.push_back(static_cast<std::uint32_t>(out.list.size()));
  }
  return out;
}

ConstraintColouring colour_constraints(const std::vector<shared::Constraint>& constraints,
                                       std::uint32_t particles) {
  // used[i]: bit c set when particle i is in a constraint of colour c (words of 64 colours).
  std::vector<std::vector<std::uint64_t>> used(particles);
  std::vector<std::uint32_t> colour(constraints.size(), 0u);
  std::uint32_t colours = 0;
  const auto taken = [&](std::uint32_t i, std::uint32_t c) {
    const std::vector<std::uint64_t>& u = used[i];
    return c / 64 < u.size() && ((u[c / 64] >> (c % 64)) & 1u) != 0;
  };
  const auto take = [&](std::uint32_t i, std::uint32_t c) {
    std::vector<std::uint64_t>& u = used[i];
    if (u.size() <= c / 64) u.resize(c / 64 + 1, 0u);
    u[c / 64] |= std::uint64_t{1} << (c % 64);
  };
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    const shared::Constraint& con = constraints[k];
    std::uint32_t c = 0;
    while (taken(con.a, c) || taken(con.b, c)) ++c;
    take(con.a, c);
    take(con.b, c);
    colour[k] = c;
    colours = std::max(colours, c + 1);
  }
  ConstraintColouring out;
  out.first.assign(colours + 1, 0u);
  for (const std::uint32_t c : colour) ++out.first[c + 1];
  for (std::uint32_t c = 0; c < colours; ++c) out.first[c + 1] += out.first[c];
  out.constraints.resize(constraints.size());
  std::vector<std::uint32_t> next(out.first.begin(), out.first.end() - 1);
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    out.constraints[next[colour[k]]++] = constraints[k];
  }
  return out;
}

}  // namespace motes
