// Soft bodies by meshless shape matching (Mueller, Heidelberger, Teschner, Gross 2005), written
// once for every backend (docs/architecture.md, "Soft bodies"). A soft body's particles are
// integrated like free spheres (particle_integrate, with their contact forces), then every cluster
// (a group of the body's particles; clusters may overlap) finds the rigid motion, or the linear or
// quadratic deformation, that best fits its particles' rest shape (clusters_fit), and every
// particle moves a fraction alpha of the way to its goal, averaged over its clusters
// (clusters_goal), its velocity changing by the same displacement / dt.
//
// Momentum: a member's mass is its particle's mass divided by the number of clusters that hold the
// particle, and the rest terms q are taken about the members' mass-weighted mean, so every
// cluster's pull sums to zero linear momentum. With the exact rotation of the polar decomposition
// the pull also adds no angular momentum about the cluster's centre (Mueller et al. 2005). In float
// neither holds well enough: the rotation is good to about 1e-7 rad and the centre to an ulp of
// the coordinates, and a pull's displacement becomes a velocity by dividing by dt, so those errors
// would give every substep a kick of linear and angular momentum (a soft box on a floor would
// creep). So the fit makes a third pass that sums, over the members, the displacement the pull
// will ask (goal - x, computed from small offsets, so precise) and its moment about the centre,
// and the pull takes the mean displacement ("drift") away and adds the rigid turn u x (x - c)
// whose moment cancels theirs (I u = -L).
#ifndef MOTES_SHARED_SHAPE_MATCHING_H
#define MOTES_SHARED_SHAPE_MATCHING_H

#include "common.h"
#include "quaternion.h"

MOTES_SHARED_BEGIN

/// Cluster.mode: what the goal may do besides rotating and translating.
#define MOTES_CLUSTER_RIGID 0u
#define MOTES_CLUSTER_LINEAR 1u
#define MOTES_CLUSTER_QUADRATIC 2u
/// Rest terms of a member: x, y, z, then x^2, y^2, z^2, xy, yz, zx (quadratic mode only).
#define MOTES_CLUSTER_TERMS 9
/// Iterations of the rotation extraction (polar_rotation), at most.
#define MOTES_CLUSTER_ROTATION_ITERATIONS 16

/// One cluster, written once at load.
struct Cluster {
  uint first;     // its first member in ClusterMembers
  uint count;     // its members
  uint mode;      // MOTES_CLUSTER_*
  float alpha;    // fraction of the way to the goal per substep, in (0, 1]
  float beta;     // linear and quadratic modes: 0 = rigid goal, 1 = the fitted deformation
  float damping;  // fraction of the members' velocity relative to the cluster's rigid motion
                  // removed per substep, in [0, 1)
  float pad1;
  float pad2;
  // The inverse of A_qq = sum m q q^T (column-major): linear mode 3 x 3 in rest[0..8], quadratic
  // mode 9 x 9; a pseudo-inverse where the rest shape is flat or a line.
  float rest[81];
  float pad3;
  float pad4;
  float pad5;
};

/// One particle's place in one cluster.
struct ClusterMember {
  uint particle;  // device particle id
  uint cluster;
  float mass;                    // the particle's mass / the number of its clusters
  float q[MOTES_CLUSTER_TERMS];  // rest terms about the cluster's mass-weighted mean (0: unused)
};

/// What clusters_fit finds, per cluster: the goal of a member at x is
/// centre + sum_k t[k] q[k] + spin x (x - centre) - drift.
struct ClusterFrame {
  vec4 rotation;    // the rotation of the polar decomposition (quaternion); starts the next fit
  vec4 centre;      // xyz: centre of mass of the members, w: the cluster's alpha
  vec4 spin;        // xyz: u, the turn that cancels the goal's angular impulse (rad)
  vec4 drift;       // xyz: the members' mass-weighted mean of goal - x (rounding), w: their mass
  vec4 velocity;    // xyz: the members' mean velocity, w: the cluster's damping
  vec4 omega;       // xyz: their angular velocity about the centre (I^-1 sum m p x v)
  vec4 damp_drift;  // xyz: as drift, for the damping's velocity changes
  vec4 damp_spin;   // xyz: as spin, for the damping's velocity changes (1/s)
  vec4 t[MOTES_CLUSTER_TERMS];  // columns of the goal transform (xyz)
};

/// A 3 x 3 matrix by columns (only in registers).
struct Mat3 {
  vec3 c0;
  vec3 c1;
  vec3 c2;
};

/// The sums a fit needs over a cluster's members, with p = x - c: A_pq = sum m p q^T by columns
/// (3, or 9 for quadratic), A_pp = sum m p p^T (diagonal, then xy, yz, zx), and for damping the
/// angular momentum sum m p x (v - V) about the centre, V the mean velocity (relative to V, so that
/// a fast translation does not drown it in rounding).
struct ClusterSums {
  vec3 apq[MOTES_CLUSTER_TERMS];
  vec3 app_diagonal;
  vec3 app_off;
  vec3 spin;
};

MOTES_FN ClusterSums cluster_sums_zero() {
  ClusterSums m;
  for (int k = 0; k < MOTES_CLUSTER_TERMS; ++k) {
    m.apq[k] = vec3(0.0f);
  }
  m.app_diagonal = vec3(0.0f);
  m.app_off = vec3(0.0f);
  m.spin = vec3(0.0f);
  return m;
}

/// Adds a member to a centre-of-mass sum: xyz += m x, w += m.
MOTES_FN vec4 cluster_centre_add(vec4 sum, vec4 pos, float mass) {
  return vec4(xyz(sum) + xyz(pos) * mass, sum.w + mass);
}

/// Adds a member to a momentum sum: += m v.
MOTES_FN vec3 cluster_momentum_add(vec3 sum, vec4 vel, float mass) { return sum + xyz(vel) * mass; }

/// Adds a member at offset p = x - c moving at v to the sums, V the members' mean velocity (A_pq:
/// the first 3 columns, or all 9 for quadratic).
MOTES_FN void cluster_sums_add(MOTES_INOUT(ClusterSums) a, vec3 offset, vec3 v, vec3 mean_v,
                               ClusterMember m, uint mode) {
  int terms = mode == MOTES_CLUSTER_QUADRATIC ? MOTES_CLUSTER_TERMS : 3;
  vec3 md = offset * m.mass;
  for (int k = 0; k < terms; ++k) {
    a.apq[k] = a.apq[k] + md * m.q[k];
  }
  a.app_diagonal = a.app_diagonal + md * offset;
  a.app_off = a.app_off + md * vec3(offset.y, offset.z, offset.x);
  a.spin = a.spin + cross(md, v - mean_v);
}

/// The rotation R that maximizes trace(R^T A), found by Mueller, Bender, Chentanez, Macklin
/// (2016, "A robust method to extract the rotational part of deformations"): turn R about
/// sum_k r_k x a_k by its length over |sum_k r_k . a_k|, starting from q (last step's rotation).
/// Never NaN: a zero, flat, line-like or inverted A gives a rotation (for A = 0, q itself).
MOTES_FN vec4 polar_rotation(Mat3 a, vec4 q) {
  float norm = sqrt(dot(a.c0, a.c0) + dot(a.c1, a.c1) + dot(a.c2, a.c2));
  if (!(norm > 1.0e-30f) || !(norm < 1.0e30f)) {
    return q;
  }
  float s = 1.0f / norm;
  vec3 a0 = a.c0 * s;
  vec3 a1 = a.c1 * s;
  vec3 a2 = a.c2 * s;
  for (int it = 0; it < MOTES_CLUSTER_ROTATION_ITERATIONS; ++it) {
    vec3 r0 = quat_rotate(q, vec3(1.0f, 0.0f, 0.0f));
    vec3 r1 = quat_rotate(q, vec3(0.0f, 1.0f, 0.0f));
    vec3 r2 = quat_rotate(q, vec3(0.0f, 0.0f, 1.0f));
    vec3 turn = cross(r0, a0) + cross(r1, a1) + cross(r2, a2);
    float along = abs(dot(r0, a0) + dot(r1, a1) + dot(r2, a2)) + 1.0e-9f;
    vec3 omega = turn * (1.0f / along);
    float angle = length(omega);
    if (!(angle > 1.0e-20f)) {
      break;
    }
    vec3 axis = omega * (1.0f / angle);
    vec4 sc = quat_sin_cos(0.5f * min(angle, 3.0f));
    q = quat_normalize(quat_mul(vec4(axis.x * sc.x, axis.y * sc.x, axis.z * sc.x, sc.y), q));
    if (angle < 1.0e-7f) {
      break;
    }
  }
  return q;
}

/// The cube root of d for d in [1e-3, 1e3], by Newton's method from above (only +, *, /: the
/// same on every backend).
MOTES_FN float cluster_cube_root(float d) {
  float x = max(d, 1.0f);
  for (int it = 0; it < 24; ++it) {
    x = (2.0f * x + d / (x * x)) * (1.0f / 3.0f);
  }
  return x;
}

/// u with I u = l for the inertia tensor I = trace(A_pp) 1 - A_pp; 0 where I is singular (a
/// cluster on a line, or a point).
MOTES_FN vec3 cluster_inertia_solve(ClusterSums s, vec3 l) {
  float tr = s.app_diagonal.x + s.app_diagonal.y + s.app_diagonal.z;
  vec3 d = vec3(tr, tr, tr) - s.app_diagonal;  // I_xx, I_yy, I_zz
  vec3 o = -s.app_off;                         // I_xy, I_yz, I_zx
  vec3 c0 = vec3(d.x, o.x, o.z);
  vec3 c1 = vec3(o.x, d.y, o.y);
  vec3 c2 = vec3(o.z, o.y, d.z);
  vec3 r0 = cross(c1, c2);
  float det = dot(c0, r0);
  if (!(det > 1.0e-6f * tr * tr * tr)) {
    return vec3(0.0f);
  }
  // I is symmetric: the rows of its inverse are the cross products of its columns over det.
  vec3 r1 = cross(c2, c0);
  vec3 r2 = cross(c0, c1);
  return vec3(dot(r0, l), dot(r1, l), dot(r2, l)) * (1.0f / det);
}

/// The frame of a cluster from its centre of mass and sums: rotation by polar_rotation (from the
/// last one), goal columns t = R (rigid), beta A / cbrt(det A) + (1 - beta) R with
/// A = A_pq A_qq^-1 (linear: volume kept; R alone where det A is outside [1e-3, 1e3], e.g. an
/// inverted or flattened cluster), or beta A~ + (1 - beta) [R 0 0] (quadratic, A~ 3 x 9); the
/// members' rigid motion (mean velocity, angular velocity) for damping. centre_mass: the centre
/// of mass and the mass; mean_v: the mean velocity. Spin and drift are 0 until
/// cluster_frame_finish.
MOTES_FN ClusterFrame cluster_frame(Cluster cl, ClusterSums sums, vec4 centre_mass, vec3 mean_v,
                                    vec4 last_rotation) {
  vec3 centre = xyz(centre_mass);
  float mass = centre_mass.w;
  ClusterFrame f;
  Mat3 a3;
  a3.c0 = sums.apq[0];
  a3.c1 = sums.apq[1];
  a3.c2 = sums.apq[2];
  vec4 q = polar_rotation(a3, last_rotation);
  f.rotation = q;
  f.centre = vec4(centre, cl.alpha);
  vec3 r[3];
  r[0] = quat_rotate(q, vec3(1.0f, 0.0f, 0.0f));
  r[1] = quat_rotate(q, vec3(0.0f, 1.0f, 0.0f));
  r[2] = quat_rotate(q, vec3(0.0f, 0.0f, 1.0f));
  for (int k = 0; k < MOTES_CLUSTER_TERMS; ++k) {
    f.t[k] = vec4(k < 3 ? r[k] : vec3(0.0f), 0.0f);
  }
  float beta = cl.beta;
  if (cl.mode == MOTES_CLUSTER_LINEAR && beta > 0.0f) {
    vec3 lin[3];
    for (int j = 0; j < 3; ++j) {
      lin[j] = sums.apq[0] * cl.rest[3 * j] + sums.apq[1] * cl.rest[3 * j + 1] +
               sums.apq[2] * cl.rest[3 * j + 2];
    }
    float det = dot(lin[0], cross(lin[1], lin[2]));
    if (det >= 1.0e-3f && det <= 1.0e3f) {
      float scale = beta / cluster_cube_root(det);
      for (int j = 0; j < 3; ++j) {
        f.t[j] = vec4(lin[j] * scale + r[j] * (1.0f - beta), 0.0f);
      }
    }
  }
  if (cl.mode == MOTES_CLUSTER_QUADRATIC && beta > 0.0f) {
    for (int j = 0; j < MOTES_CLUSTER_TERMS; ++j) {
      vec3 col = vec3(0.0f);
      for (int k = 0; k < MOTES_CLUSTER_TERMS; ++k) {
        col = col + sums.apq[k] * cl.rest[MOTES_CLUSTER_TERMS * j + k];
      }
      f.t[j] = vec4(col * beta + xyz(f.t[j]) * (1.0f - beta), 0.0f);
    }
  }
  f.spin = vec4(0.0f);
  f.drift = vec4(0.0f, 0.0f, 0.0f, mass);
  f.velocity = vec4(mean_v, cl.damping);
  f.omega = vec4(cluster_inertia_solve(sums, sums.spin), 0.0f);
  f.damp_drift = vec4(0.0f);
  f.damp_spin = vec4(0.0f);
  return f;
}

/// goal - x for a member whose particle is at x, before spin and drift: summed from -(x - c)
/// and the goal's terms, never as goal - x of two rounded coordinates, so that it keeps the
/// precision of the body's size rather than of its distance from the origin. clusters_fit's third
/// pass and clusters_goal compute it identically, so the drift they see is the same to the bit.
MOTES_FN vec3 cluster_goal_offset(ClusterFrame f, ClusterMember m, vec3 x) {
  vec3 g = -(x - xyz(f.centre));
  for (int k = 0; k < MOTES_CLUSTER_TERMS; ++k) {
    g = g + xyz(f.t[k]) * m.q[k];
  }
  return g;
}

/// The velocity change toward the cluster's rigid motion for a member at x moving at v, before
/// corrections and weights: (V - v) + omega x (x - c).
MOTES_FN vec3 cluster_damp_offset(ClusterFrame f, vec3 x, vec3 v) {
  return (xyz(f.velocity) - v) + cross(xyz(f.omega), x - xyz(f.centre));
}

/// The sums of clusters_fit's third pass over the members, each mass-weighted: the pull a member
/// would get from a frame without spin or drift, and its moment about the centre; the same for
/// the damping's velocity change.
struct ClusterPulls {
  vec3 drift;
  vec3 moment;
  vec3 damp_drift;
  vec3 damp_moment;
};

MOTES_FN ClusterPulls cluster_pulls_zero() {
  ClusterPulls s;
  s.drift = vec3(0.0f);
  s.moment = vec3(0.0f);
  s.damp_drift = vec3(0.0f);
  s.damp_moment = vec3(0.0f);
  return s;
}

/// Adds a member at x moving at v to the third pass's sums.
MOTES_FN void cluster_pulls_add(MOTES_INOUT(ClusterPulls) s, ClusterFrame f, ClusterMember m,
                                vec3 x, vec3 v) {
  vec3 p = x - xyz(f.centre);
  vec3 pull = cluster_goal_offset(f, m, x) * m.mass;
  s.drift = s.drift + pull;
  s.moment = s.moment + cross(p, pull);
  vec3 damp = cluster_damp_offset(f, x, v) * m.mass;
  s.damp_drift = s.damp_drift + damp;
  s.damp_moment = s.damp_moment + cross(p, damp);
}

/// Spin and drift of a frame, and the damping's, from the third pass's sums.
MOTES_FN ClusterFrame cluster_frame_finish(ClusterFrame f, ClusterSums sums, ClusterPulls s) {
  float inv_mass = 1.0f / f.drift.w;
  f.spin = vec4(-cluster_inertia_solve(sums, s.moment), 0.0f);
  f.drift = vec4(s.drift * inv_mass, f.drift.w);
  f.damp_spin = vec4(-cluster_inertia_solve(sums, s.damp_moment), 0.0f);
  f.damp_drift = vec4(s.damp_drift * inv_mass, 0.0f);
  return f;
}

/// The velocity change one cluster's damping asks of its member's particle (at x, moving at v):
/// the damping fraction of the difference from the cluster's rigid motion (drift and spin
/// corrected, as the pull's), weighted by the member's share of the particle's mass. Keeps the
/// cluster's momentum and angular momentum.
MOTES_FN vec3 cluster_damp(ClusterFrame f, ClusterMember m, vec3 x, vec3 v, float inv_mass) {
  vec3 change = (cluster_damp_offset(f, x, v) - xyz(f.damp_drift)) +
                cross(xyz(f.damp_spin), x - xyz(f.centre));
  return change * (f.velocity.w * m.mass * inv_mass);
}

/// The displacement one cluster asks of its member's particle (at x, inverse mass inv_mass):
/// alpha (goal - x - drift + spin x (x - c)), weighted by the member's share of the particle's
/// mass. The small terms are added after the offset, whose cancellation is the only large one.
MOTES_FN vec3 cluster_shift(ClusterFrame f, ClusterMember m, vec3 x, float inv_mass) {
  vec3 pull = (cluster_goal_offset(f, m, x) - xyz(f.drift)) + cross(xyz(f.spin), x - xyz(f.centre));
  return pull * (f.centre.w * m.mass * inv_mass);
}

MOTES_SHARED_END

#ifdef __cplusplus
static_assert(sizeof(motes::shared::Cluster) == 368, "Cluster layout");
static_assert(sizeof(motes::shared::ClusterMember) == 48, "ClusterMember layout");
static_assert(sizeof(motes::shared::ClusterFrame) == 272, "ClusterFrame layout");
#endif

#endif  // MOTES_SHARED_SHAPE_MATCHING_H
