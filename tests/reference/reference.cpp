// The reference oracle: naive serial loops, written from the kernels' definitions (see
// reference.h). Deliberately simple: no grid in contacts_compute, std::stable_sort in grid_build.
#include "reference.h"

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <stdexcept>

#include "shared/body_math.h"
#include "shared/contact_force.h"
#include "shared/grid_hash.h"
#include "shared/motion_check.h"
#include "shared/neighbours.h"

namespace motes_ref {

using motes::shared::vec3;
using motes::shared::xyz;

Grid grid_build(const Particles& particles, const StepParams& p) {
  const std::size_t n = particles.size();
  const std::size_t table = std::size_t{p.table_mask} + 1;
  Grid g;
  g.bucket.assign(n, 0u);
  for (std::size_t i = 0; i < n; ++i) {
    const vec4 x = particles.pos[i];
    g.bucket[i] = motes::shared::grid_bucket(motes::shared::grid_cell_coord(x.x, p.inv_cell_size),
                                             motes::shared::grid_cell_coord(x.y, p.inv_cell_size),
                                             motes::shared::grid_cell_coord(x.z, p.inv_cell_size),
                                             p.table_mask);
  }
  g.order.assign(n, 0u);
  std::iota(g.order.begin(), g.order.end(), uint{0});
  std::stable_sort(g.order.begin(), g.order.end(),
                   [&](uint a, uint b) { return g.bucket[a] < g.bucket[b]; });

  // cell_start[b] = first sorted position whose bucket is >= b (a linear scan, one bucket at a
  // time); cell_start[T] = N.
  g.cell_start.assign(table + 1, 0u);
  std::size_t s = 0;
  for (std::size_t b = 0; b <= table; ++b) {
    while (s < n && g.bucket[g.order[s]] < b) ++s;
    g.cell_start[b] = static_cast<uint>(s);
  }

  g.sorted_pos.assign(n, vec4(0.0f));
  g.sorted_body.assign(n, 0u);
  for (std::size_t k = 0; k < n; ++k) {
    const uint i = g.order[k];
    g.sorted_pos[k] = particles.pos[i];
    g.sorted_body[k] = particles.body[i];
  }
  return g;
}

std::vector<uint> walk_buckets(vec4 x, const StepParams& p) {
  using motes::shared::grid_cell_coord;
  const int cx = grid_cell_coord(x.x, p.inv_cell_size);
  const int cy = grid_cell_coord(x.y, p.inv_cell_size);
  const int cz = grid_cell_coord(x.z, p.inv_cell_size);
  std::vector<uint> seq;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const uint b = motes::shared::grid_bucket(cx + dx, cy + dy, cz + dz, p.table_mask);
        if (std::find(seq.begin(), seq.end(), b) == seq.end()) seq.push_back(b);
      }
    }
  }
  return seq;
}

Neighbours neighbours_build(const Particles& particles, const Grid& grid, const StepParams& p) {
  const std::size_t n = particles.size();
  std::vector<uint> slot(n, 0u);
  for (std::size_t s = 0; s < n; ++s) slot[grid.order[s]] = static_cast<uint>(s);
  Neighbours out;
  out.lists.resize(n);
  out.count.assign(n, 0u);
  out.ref = particles.pos;
  for (std::size_t i = 0; i < n; ++i) {
    if (particles.vel[i].w == 0.0f) continue;  // static: no list
    const std::vector<uint> walk = walk_buckets(particles.pos[i], p);
    std::vector<std::pair<std::size_t, uint>> found;  // (place on the walk, slot) of each j
    const vec4 xi = particles.pos[i];
    for (std::size_t j = 0; j < n; ++j) {
      // Every test must pass, so the cheapest (the distance) goes first: at 20,000 particles the
      // walk's search and the set lookup for every pair were most of the conformance suite's time.
      // Apart along x by the cutoff or more: neighbour_within says no (dx * dx alone reaches it).
      const vec4 xj = particles.pos[j];
      const float dx = xj.x - xi.x;
      const float cutoff = (xi.w + xj.w) + p.neighbour_skin;
      if (dx >= cutoff || -dx >= cutoff) continue;
      if (!motes::shared::neighbour_within(xi, xj, p.neighbour_skin)) continue;
      if (motes::shared::contact_excluded(particles.body[j], particles.body[i]) ||
          particles.never_touch.count({uint(i), uint(j)}) != 0) {
        continue;  // j == i, or j never touches i
      }
      const auto on_walk = std::find(walk.begin(), walk.end(), grid.bucket[j]);
      if (on_walk == walk.end()) continue;
      found.emplace_back(static_cast<std::size_t>(on_walk - walk.begin()), slot[j]);
    }
    std::sort(found.begin(), found.end());
    for (const auto& [place, s] : found) out.lists[i].push_back(grid.order[s]);
    const auto c = static_cast<uint>(found.size());
    out.count[i] = c;
    out.over_capacity += c > p.neighbour_capacity ? 1u : 0u;
    out.max_count = std::max(out.max_count, c);
  }
  return out;
}

std::vector<vec4> contacts_compute(const Particles& particles, const std::vector<ContactLaw>& laws,
                                   const std::vector<PlaneData>& planes, const StepParams& p) {
  const std::size_t n = particles.size();
  const std::size_t m = p.material_count;
  std::vector<vec4> force(n, vec4(0.0f));
  for (std::size_t i = 0; i < n; ++i) {
    const vec4 xi = particles.pos[i];
    const vec4 vi = particles.vel[i];
    if (vi.w == 0.0f) continue;  // static particles get no force
    double sum[3] = {0.0, 0.0, 0.0};
    auto add = [&](vec3 f) {
      sum[0] += static_cast<double>(f.x);
      sum[1] += static_cast<double>(f.y);
      sum[2] += static_cast<double>(f.z);
    };
    for (std::size_t j = 0; j < n; ++j) {
      const vec4 xj = particles.pos[j];
      // Apart along x by the radii's sum or more: particle_contact_force returns 0 (its float
      // dx * dx alone reaches rsum * rsum), which adds nothing.
      const float dx = xj.x - xi.x;
      if (dx >= xi.w + xj.w || -dx >= xi.w + xj.w) continue;
      const vec4 vj = particles.vel[j];
      const ContactLaw law = laws[particles.material[i] * m + particles.material[j]];
      const vec3 f = motes::shared::particle_contact_force(xyz(xi), xyz(vi), xi.w, vi.w, xyz(xj),
                                                           xyz(vj), xj.w, vj.w, law, p.flags);
      // A zero term adds nothing (the sum starts at +0 and so is never -0): the exclusions, a set
      // lookup, are asked only of pairs that touch.
      if (f.x == 0.0f && f.y == 0.0f && f.z == 0.0f) continue;
      if (motes::shared::contact_excluded(particles.body[j], particles.body[i]) ||
          particles.never_touch.count({uint(i), uint(j)}) != 0) {
        continue;  // j == i, or j never touches i
      }
      add(f);
    }
    for (std::size_t k = 0; k < p.plane_count; ++k) {
      const ContactLaw law = laws[particles.material[i] * m + planes[k].material];
      add(motes::shared::plane_contact_force(xyz(xi), xyz(vi), xi.w, vi.w, planes[k].normal_offset,
                                             law, p.flags));
    }
    force[i] = vec4(static_cast<float>(sum[0]), static_cast<float>(sum[1]),
                    static_cast<float>(sum[2]), 0.0f);
  }
  return force;
}

void bodies_reduce(const std::vector<vec4>& particle_pos, const std::vector<vec4>& particle_force,
                   Bodies& bodies) {
  const std::size_t count = bodies.size();
  bodies.force.assign(count, vec4(0.0f));
  bodies.torque.assign(count, vec4(0.0f));
  for (std::size_t b = 0; b < count; ++b) {
    const vec4 com = bodies.pos[b];
    if (com.w == 0.0f) continue;  // static bodies: nothing to integrate, zero sums
    vec3 f(0.0f);
    vec3 tau(0.0f);
    for (uint i = bodies.first[b]; i < bodies.first[b + 1]; ++i) {
      f += xyz(particle_force[i]);
      tau += motes::shared::particle_torque(particle_pos[i], com, particle_force[i]);
    }
    bodies.force[b] = vec4(f, 0.0f);
    bodies.torque[b] = vec4(tau, 0.0f);
  }
}

void bodies_integrate(Bodies& bodies, const StepParams& p) {
  bodies.angvel.assign(bodies.size(), vec4(0.0f));
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    motes::shared::body_integrate(bodies.pos[b], bodies.quat[b], bodies.vel[b], bodies.angmom[b],
                                  bodies.angvel[b], bodies.inv_inertia[b], bodies.force[b],
                                  bodies.torque[b], p.gravity_dt, p.flags);
  }
}

void bodies_push_pose(Bodies& bodies, const std::vector<vec4>& vel_push,
                      const std::vector<vec4>& angmom_push, const StepParams& p) {
  bodies.angvel.assign(bodies.size(), vec4(0.0f));
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    motes::shared::body_push_pose(bodies.pos[b], bodies.quat[b], bodies.angvel[b],
                                  bodies.inv_inertia[b], bodies.angmom[b], vel_push[b],
                                  angmom_push[b], p.gravity_dt);
  }
}

bool particles_update(const Bodies& bodies, Particles& particles, const StepParams& p,
                      const std::vector<vec4>& ref) {
  bool moved = false;
  for (std::size_t i = 0; i < particles.rigid; ++i) {
    const uint b = particles.body[i];
    const vec4 local = particles.local[i];
    particles.pos[i] = vec4(motes::shared::particle_position(bodies.pos[b], bodies.quat[b], local),
                            particles.pos[i].w);
    particles.vel[i] = vec4(
        motes::shared::particle_velocity(bodies.quat[b], bodies.vel[b], bodies.angvel[b], local),
        particles.vel[i].w);
    if (!ref.empty()) {
      moved = motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
              moved;
    }
  }
  return moved;
}

void absorbed_impulses(const Bodies& bodies, const Particles& particles, std::vector<vec4>& impulse,
                       std::vector<vec4>& moment) {
  impulse.assign(particles.rigid, vec4(0.0f));
  moment.assign(particles.rigid, vec4(0.0f));
  for (std::size_t i = 0; i < particles.rigid; ++i) {
    const uint b = particles.body[i];
    const vec3 j = motes::shared::particle_absorbed_impulse(
        particles.vel[i], bodies.quat[b], bodies.vel[b], bodies.angvel[b], particles.local[i]);
    impulse[i] = vec4(j, 0.0f);
    const vec3 r = motes::shared::quat_rotate(bodies.quat[b], xyz(particles.local[i]));
    moment[i] = vec4(motes::shared::cross(r, j), 0.0f);
  }
}

std::vector<uint> particles_check(const Particles& particles) {
  using namespace motes::shared;  // NOLINT: the MotionCheck helpers
  std::vector<uint> words = {0u, MOTES_MOTION_NONE, MOTES_MOTION_NONE, 0u};
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (!motion_finite(particles.pos[i], particles.vel[i])) {
      if (words[MOTES_MOTION_NON_FINITE] == MOTES_MOTION_NONE) {
        words[MOTES_MOTION_NON_FINITE] = static_cast<uint>(i);
      }
    } else {
      words[MOTES_MOTION_RATE2] = std::max(words[MOTES_MOTION_RATE2],
                                           motion_rate2_bits(particles.pos[i], particles.vel[i]));
    }
  }
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (motion_finite(particles.pos[i], particles.vel[i]) &&
        motion_rate2_bits(particles.pos[i], particles.vel[i]) == words[MOTES_MOTION_RATE2]) {
      words[MOTES_MOTION_FASTEST] = static_cast<uint>(i);
      words[MOTES_MOTION_SPEED2] = float_bits(motion_speed2(particles.vel[i]));
      break;
    }
  }
  return words;
}

bool particles_integrate(Particles& particles, const std::vector<vec4>& force, const StepParams& p,
                         const std::vector<vec4>& ref) {
  bool moved = false;
  for (std::size_t i = particles.rigid; i < particles.size(); ++i) {
    if (i >= p.linked_first) {  // cloth and rope particles: Jakobsen's damping first
      const vec4 v = particles.vel[i];
      const float keep = 1.0f - p.linked_damping;
      particles.vel[i] = vec4(v.x * keep, v.y * keep, v.z * keep, v.w);
    }
    motes::shared::particle_integrate(particles.pos[i], particles.vel[i], force[i], p.gravity_dt);
    if (!ref.empty()) {
      moved = motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
              moved;
    }
  }
  return moved;
}

bool constraints_solve(Particles& particles, const std::vector<Constraint>& constraints,
                       const StepParams& p, const std::vector<vec4>& ref) {
  const float inv_dt = 1.0f / p.gravity_dt.w;
  std::vector<bool> used(particles.size(), false);
  bool moved = false;
  for (std::size_t k = p.constraint_first; k < p.constraint_first + p.constraint_count; ++k) {
    const Constraint c = constraints[k];
    if (used[c.a] || used[c.b] || c.a == c.b) {
      throw std::invalid_argument(
          "constraints_solve: two constraints of one colour share a particle");
    }
    used[c.a] = used[c.b] = true;
    const float wa = particles.vel[c.a].w;
    const float wb = particles.vel[c.b].w;
    const vec3 d = motes::shared::constraint_correction(particles.pos[c.a], particles.pos[c.b], wa,
                                                        wb, c.rest, c.stiffness);
    motes::shared::constraint_apply(particles.pos[c.a], particles.vel[c.a], d * wa, inv_dt);
    motes::shared::constraint_apply(particles.pos[c.b], particles.vel[c.b], d * -wb, inv_dt);
    for (const uint i : {c.a, c.b}) {
      if (!ref.empty() && (p.flags & MOTES_FLAG_SKIN_CHECK) != 0) {
        moved =
            motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
            moved;
      }
    }
  }
  return moved;
}

void clusters_fit(const std::vector<vec4>& pos, const std::vector<vec4>& vel,
                  const std::vector<Cluster>& clusters, const std::vector<ClusterMember>& members,
                  std::vector<ClusterFrame>& frames) {
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    const Cluster& cl = clusters[k];
    vec4 sum(0.0f);
    vec3 momentum(0.0f);
    for (uint j = cl.first; j < cl.first + cl.count; ++j) {
      sum = motes::shared::cluster_centre_add(sum, pos[members[j].particle], members[j].mass);
      momentum =
          motes::shared::cluster_momentum_add(momentum, vel[members[j].particle], members[j].mass);
    }
    const vec3 centre = motes::shared::xyz(sum) / sum.w;
    const vec3 mean_v = momentum / sum.w;
    motes::shared::ClusterSums sums = motes::shared::cluster_sums_zero();
    for (uint j = cl.first; j < cl.first + cl.count; ++j) {
      motes::shared::cluster_sums_add(sums, motes::shared::xyz(pos[members[j].particle]) - centre,
                                      motes::shared::xyz(vel[members[j].particle]), mean_v,
                                      members[j], cl.mode);
    }
    ClusterFrame f =
        motes::shared::cluster_frame(cl, sums, vec4(centre, sum.w), mean_v, frames[k].rotation);
    motes::shared::ClusterPulls pulls = motes::shared::cluster_pulls_zero();
    for (uint j = cl.first; j < cl.first + cl.count; ++j) {
      motes::shared::cluster_pulls_add(pulls, f, members[j], xyz(pos[members[j].particle]),
                                       xyz(vel[members[j].particle]));
    }
    frames[k] = motes::shared::cluster_frame_finish(f, sums, pulls);
  }
}

bool clusters_goal(Particles& particles, const std::vector<ClusterMember>& members,
                   const std::vector<ClusterFrame>& frames, const StepParams& p,
                   const std::vector<vec4>& ref) {
  std::vector<vec3> shift(particles.size(), vec3(0.0f));
  std::vector<vec3> damp(particles.size(), vec3(0.0f));
  for (const ClusterMember& m : members) {
    if (m.particle < p.soft_first || m.particle >= p.linked_first) {
      throw std::invalid_argument("clusters_goal: a member outside the soft particles");
    }
    const vec3 x = xyz(particles.pos[m.particle]);
    const vec4 v = particles.vel[m.particle];
    shift[m.particle] += motes::shared::cluster_shift(frames[m.cluster], m, x, v.w);
    damp[m.particle] += motes::shared::cluster_damp(frames[m.cluster], m, x, xyz(v), v.w);
  }
  const float inv_dt = 1.0f / p.gravity_dt.w;
  bool moved = false;
  for (uint i = p.soft_first; i < p.linked_first; ++i) {
    particles.vel[i] = vec4(xyz(particles.vel[i]) + damp[i], particles.vel[i].w);
    motes::shared::constraint_apply(particles.pos[i], particles.vel[i], shift[i], inv_dt);
    if (!ref.empty()) {
      moved = motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
              moved;
    }
  }
  return moved;
}

void step(Particles& particles, Bodies& bodies, const std::vector<ContactLaw>& laws,
          const std::vector<PlaneData>& planes, const StepParams& p) {
  const std::vector<vec4> force = contacts_compute(particles, laws, planes, p);
  bodies_reduce(particles.pos, force, bodies);
  bodies_integrate(bodies, p);
  particles_update(bodies, particles, p);
  particles_integrate(particles, force, p);
}

}  // namespace motes_ref
