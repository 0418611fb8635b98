// Position contacts (docs/architecture.md, "Position contacts"; docs/position-solver.md): rigid
// bodies made of particles meet each other and the planes as position constraints, solved once
// per substep on the poses predicted with gravity (Macklin et al. 2019, "Small steps"), as Müller
// et al. 2020 ("Detailed rigid body simulation with extended position based dynamics") correct
// rigid poses:
// - projection: a contact of bodies a and b with normal n (from b towards a) and overlap d > 0
//   is the constraint C = d; its correction p = d / (w_a + w_b) n, with the generalized inverse
//   masses w = 1/m + (r x n) . I^-1 (r x n), moves a's centre by p / m_a and turns it by
//   I^-1 (r_a x p) (b the opposite way). Static friction is positional: the contact keeps an
//   anchor (where it stuck) and its drift from it along the contact plane is undone while the
//   tangential correction stays below mu times the normal one, else it is capped there (Macklin
//   et al. 2014, eq. 24, with one mu for both; the anchor is Müller et al. 2020's difference of
//   contact points kept across substeps): a sticking contact goes back to where it stuck, so a
//   resting pile cannot creep; a sliding one loses mu g per unit time of its speed, in every
//   sweep (the later ones against its sliding velocity).
//   The points are the particles' centres, as in particle-based solvers (Macklin et al. 2014):
//   the anchor measures their drift and the correction acts there (arm r = x_particle - x_com),
//   so the quantity corrected is the one the correction moves. A correction measured at the
//   centres and applied on the particles' surfaces spins a body whose inertia about that lever is
//   small (a rod of particles about its axis) instead of moving the centres, and the spin grows
//   with the drift it leaves (docs/position-solver.md). The normal part is the same at either
//   point (they lie on the normal); the friction part means a body one particle thick about an
//   axis (a single sphere, a rod) slides to a stop rather than rolling.
// - velocities: each body keeps the motion its pose made as velocity (v += p / (m h), and the
//   same for the angular momentum), as PBD's v = (x - x_start) / h does;
// - velocity pass (Müller et al. 2020, section 3.5): each contact the projection had sets its
//   normal velocity to -e vn0 (vn0 its normal velocity at the substep's start) when it closed
//   faster than MOTES_POSITION_BOUNCE_SUBSTEPS substeps of gravity, else to 0, so that the
//   speed a correction gave a body is taken back rather than kept; a contact the projection kept
//   stuck loses its tangential velocity too.
// Departure from Müller 2020: Jacobi with mass splitting instead of Gauss-Seidel, as the impulse
// contacts do (shared/impulse.h): every contact of a body with n contacts sees it with n times its
// inverse mass and inertia, all contacts are solved from the same poses, each body sums its
// particles' corrections in particle order: no atomics, the same integers on every backend.
// Jacobi moves a body between two contacts only part of the way, so a column of bodies would be
// a chain of soft springs: the lower body of a resting contact counts as heavier
// (position_stack_scale, Macklin et al. 2014's mass scaling), the projection runs three sweeps a
// substep (core/src/simulation.cpp), a contact projected in one stays one to the substep's end,
// and the velocity pass stops the contacts the projection kept stuck; columns of ten boxes and
// pyramids stand (docs/position-solver.md has the measurements).
// A correction travels as an impulse, J = p / h, through the buffers the impulse contacts use, so
// that impulses_compute and impulses_apply run both models.
#ifndef MOTES_SHARED_POSITION_H
#define MOTES_SHARED_POSITION_H

#include "body_math.h"
#include "common.h"
#include "contact_body.h"
#include "params.h"
#include "quaternion.h"

MOTES_SHARED_BEGIN

/// A contact closing faster than this many substeps' worth of gravity bounces (Müller et al.
/// 2020 use 2); resting contacts close at |g| h every substep and do not.
#define MOTES_POSITION_BOUNCE_SUBSTEPS 2.0f

/// f = size / (size + |dh|) of two bodies whose centres are dh apart along -gravity (g: |gravity|),
/// negated when a is the lower (b lower: positive; level or no gravity: -1, no scaling): the
/// height part of position_stack_scale and contact_stack_scale.
MOTES_FN float stack_height_scale(vec3 com_a, vec3 com_b, float size, float g, vec4 gravity_dt) {
  float dh = g > 0.0f ? -dot(com_a - com_b, xyz(gravity_dt)) / g : 0.0f;
  float f = size / (size + abs(dh));
  return dh > 0.0f ? f : -f;
}

/// Mass scaling of resting contacts in stacks (Macklin et al. 2014, section 5.1, without the
/// exponential, whose bits differ between backends): in a contact of bodies whose centres are dh
/// apart along -gravity, the lower body's inverse mass and inertia count f = size / (size + |dh|)
/// of themselves (size: the pair's particle diameter), so the upper body takes most of the
/// correction. A box of three particles' height on another takes 4/5 of it (f = 1/4); bodies
/// side by side (dominoes, a row of a pyramid) are scaled by about 1. Only for contacts closing
/// slower than a bounce (restitution and collisions keep their momentum) and never without
/// gravity. Returns f, negated when the lower body is a (b is lower: positive; 1: no scaling).
MOTES_FN float position_stack_scale(vec3 com_a, vec3 com_b, float size, float vn0,
                                    vec4 gravity_dt) {
  float g = length(xyz(gravity_dt));
  if (!(g > 0.0f) || vn0 < -MOTES_POSITION_BOUNCE_SUBSTEPS * g * gravity_dt.w) {
    return 1.0f;
  }
  return stack_height_scale(com_a, com_b, size, g, gravity_dt);
}

/// The factor a stack scale s (position_stack_scale, contact_stack_scale) puts on side a
/// (side_b false) or side b of a contact: the lower body's f, 1 for the other.
MOTES_FN float stack_side_scale(float s, bool side_b) {
  return side_b ? (s > 0.0f ? s : 1.0f) : (s < 0.0f ? -s : 1.0f);
}

/// The inverse mass the velocity pass's normal step meets at body b (arm r, normal n): the bound
/// of its contacts' Gram matrix (shared/contact_gram.h; BodyAngVelStart.w, made by the counting
/// pass with MOTES_FLAG_POSITION_GRAM), never less than the contact's own 1/m + (r x n) . I^-1
/// (r x n) (a contact the count did not see); mass splitting where no bound was made. 0 for a
/// wall or a static body.
MOTES_FN float position_velocity_inverse_mass(MOTES_IN(ImpulseBody) b, vec3 r, vec3 n) {
  if (b.com.w == 0.0f) return 0.0f;
  if (!(b.angvel0.w > 0.0f)) return impulse_inverse_mass(b, r, n);
  vec3 rn = cross(r, n);
  return max(b.angvel0.w, b.com.w + dot(rn, impulse_inverse_inertia(b, rn)));
}

/// What a position contact does to each of its two bodies (xyz: the impulse, w: 1 for a contact
/// that overlaps, else 0).
struct PositionPair {
  vec4 a;
  vec4 b;
};

/// The part of v along a contact's plane (normal n): its length len and unit direction t, and
/// the contact's inverse mass along t, kt (sa, sb: the bodies' stack scaling); all 0 when v has
/// no such part.
struct PositionTangent {
  vec3 t;
  float len;
  float kt;
};

MOTES_FN PositionTangent position_tangent(vec3 v, vec3 n, MOTES_IN(ImpulseBody) a, vec3 ra,
                                          float sa, MOTES_IN(ImpulseBody) b, vec3 rb, float sb) {
  PositionTangent r;
  r.t = vec3(0.0f);
  r.len = 0.0f;
  r.kt = 0.0f;
  vec3 vt = v - n * dot(v, n);
  float len2 = dot(vt, vt);
  if (len2 > 0.0f) {
    r.len = sqrt(len2);
    r.t = vt / r.len;
    r.kt = sa * impulse_inverse_mass(a, ra, r.t) + sb * impulse_inverse_mass(b, rb, r.t);
  }
  return r;
}

/// The position contact of bodies a and b through points ca of a and cb of b (their particles'
/// centres; a plane's point for a wall), normal n (unit, from b towards a), separation sep
/// (< 0: overlap), particle diameter size: the impulse on each body and whether it
/// counts (PositionPair). The lower body of a resting contact counts as heavier
/// (position_stack_scale) in the projection and the velocity pass.
/// acc, the contact's memory (its slot, as the lower particle id sees it): xyz its friction
/// anchor, where rel (a's particle relative to b) was when the contact stuck (never 0 for a real
/// anchor: 0 is none), w whether a sweep of this substep projected it: 1 while it sticks, -1 once
/// it slid, 0 not projected (the first sweep, flagged MOTES_FLAG_POSITION_FIRST, starts anew).
/// - with MOTES_FLAG_IMPULSE_COUNT: only the count (the bodies' contact counts, which scale the
///   inverse masses: mass splitting, are known after it); the anchor kept while the contact
///   overlaps;
/// - with MOTES_FLAG_POSITION_VELOCITY: the velocity pass, from the velocities now (vel, angvel)
///   and those before the projection (vel0, angvel0);
/// - else the projection: (d n / (w_a + w_b) - the friction correction) / h on a, its negation
///   on b. Static friction takes rel back to its anchor along the contact plane (a new contact
///   anchors where it was at the substep's start, rel - u h): a drift of many substeps, each too
///   small to see, is undone as a whole, so a body on a bumpy support cannot creep. Past mu times
///   the normal correction the contact slides: the correction is capped and the anchor follows
///   what is left; in the substep's later sweeps a contact that slid meets kinetic friction
///   (mu times each sweep's normal correction) against its sliding velocity, never past
///   stopping, and keeps its anchor.
MOTES_FN PositionPair contact_position(MOTES_IN(ImpulseBody) a, MOTES_IN(ImpulseBody) b, vec3 ca,
                                       vec3 cb, vec3 n, float sep, float size, vec3 rel,
                                       ContactLaw law, vec4 gravity_dt, uint flags,
                                       MOTES_INOUT(vec4) acc) {
  PositionPair res;
  res.a = vec4(0.0f);
  res.b = vec4(0.0f);
  // A contact an earlier sweep of this substep projected (acc.w != 0) stays one until the
  // substep ends, overlapping or not: it keeps its anchor and counts, and the velocity pass sets
  // its normal velocity.
  bool had = (flags & MOTES_FLAG_POSITION_FIRST) == 0u && acc.w != 0.0f;
  bool overlaps = sep < 0.0f;
  if (!overlaps && !had) {
    acc = vec4(0.0f);
    return res;
  }
  // Counted; with MOTES_FLAG_POSITION_GRAM the normal goes with the count, for its n n^T
  // (shared/contact_gram.h: the velocity pass's step).
  vec3 gram = (flags & MOTES_FLAG_POSITION_GRAM) != 0u ? n : vec3(0.0f);
  res.a = vec4(gram, 1.0f);
  res.b = vec4(gram, 1.0f);
  if ((flags & MOTES_FLAG_IMPULSE_COUNT) != 0u ||
      (!overlaps && (flags & MOTES_FLAG_POSITION_VELOCITY) == 0u)) {
    return res;
  }
  float h = gravity_dt.w;
  vec3 ra = ca - xyz(a.com);
  vec3 rb = cb - xyz(b.com);
  vec3 u0 =
      impulse_point_velocity(a.vel0, a.angvel0, ra) - impulse_point_velocity(b.vel0, b.angvel0, rb);
  float vn0 = dot(u0, n);
  float f = position_stack_scale(xyz(a.com), xyz(b.com), size, vn0, gravity_dt);
  float sa = stack_side_scale(f, false);
  float sb = stack_side_scale(f, true);
  float kn = sa * impulse_inverse_mass(a, ra, n) + sb * impulse_inverse_mass(b, rb, n);
  if (!(kn > 0.0f)) {
    return res;
  }
  vec3 u =
      impulse_point_velocity(a.vel, a.angvel, ra) - impulse_point_velocity(b.vel, b.angvel, rb);
  if ((flags & MOTES_FLAG_POSITION_VELOCITY) != 0u) {
    float bounce_speed = MOTES_POSITION_BOUNCE_SUBSTEPS * length(xyz(gravity_dt)) * h;
    // Bounce; else neither approach nor separation (Müller et al. 2020's rule: a contact that
    // is still overlapping after it bounced loses what separation speed it has left).
    float target = vn0 < -bounce_speed ? -law.restitution * vn0 : 0.0f;
    // The normal step by the bodies' Gram bounds (shared/contact_gram.h), which converges where
    // mass splitting's does not (a flat face's contacts).
    float kv = sa * position_velocity_inverse_mass(a, ra, n) +
               sb * position_velocity_inverse_mass(b, rb, n);
    vec3 j = n * ((target - dot(u, n)) / kv);
    // A contact the projection kept stuck (acc.w > 0; the projection's Coulomb test passed) ends
    // the substep without tangential speed: its return to an anchor some substeps old is not
    // kept as speed past it. Müller et al. 2020 anchor at the substep's start, so the velocity
    // they derive from a stuck contact has no tangential part either.
    if (acc.w > 0.0f) {
      PositionTangent ut = position_tangent(u, n, a, ra, sa, b, rb, sb);
      if (ut.kt > 0.0f) {
        j -= ut.t * (ut.len / ut.kt);
      }
    }
    res.a = vec4(j * sa, 1.0f);
    res.b = vec4(-j * sb, 1.0f);
    return res;
  }
  float ln = -sep / kn;
  vec3 p = n * ln;
  bool anchored = acc.x != 0.0f || acc.y != 0.0f || acc.z != 0.0f;
  vec3 anchor = anchored ? xyz(acc) : rel - u * h;
  bool first = (flags & MOTES_FLAG_POSITION_FIRST) != 0u;
  bool stuck = law.friction != 0.0f && (first || acc.w > 0.0f);
  // A contact that slid in the substep's first sweep slides on in the later ones: kinetic
  // friction on their normal corrections, against its sliding velocity, never past stopping.
  bool slid = !first && acc.w < 0.0f;
  if (slid && law.friction > 0.0f) {
    PositionTangent ut = position_tangent(u, n, a, ra, sa, b, rb, sb);
    if (ut.kt > 0.0f) {
      p -= ut.t * min(law.friction * ln, ut.len * h / ut.kt);
    }
  } else if (law.friction != 0.0f) {
    PositionTangent dt = position_tangent(rel - anchor, n, a, ra, sa, b, rb, sb);
    if (dt.kt > 0.0f) {
      float lt = dt.len / dt.kt;
      if (law.friction > 0.0f && lt > law.friction * ln) {
        lt = law.friction * ln;
        // Sliding: the anchor follows what is not undone. Only in the substep's first sweep,
        // where the predicted motion is: a contact that stuck there keeps its anchor through
        // the later sweeps, whose share of the normal correction may be too small to hold it,
        // and a drift they cannot undo is left for the next substep's first, not let slide.
        if (first) {
          anchor += dt.t * (dt.len - lt * dt.kt);
          stuck = false;
        }
      }
      p -= dt.t * lt;
    }
  }
  acc = vec4(anchor, stuck ? 1.0f : -1.0f);
  res.a = vec4(p * (sa / h), 1.0f);
  res.b = vec4(-p * (sb / h), 1.0f);
  return res;
}

/// Where a particle touching a plane is, for the contact's friction anchor (contact_position's
/// rel): its contact point c's part along the plane, plus the plane's unit normal np, so that it
/// is never 0 (0 means no anchor).
MOTES_FN vec3 plane_contact_rel(vec3 c, vec3 np) { return c - np * dot(np, c) + np; }

/// A body's pose and velocities after its position contacts (impulses_apply with
/// MOTES_FLAG_POSITION): impulse = sum of J = p / h over its contacts, moment = sum of
/// (c - x_com) x J. The centre moves by h impulse / m, the orientation turns by
/// h I^-1(q) moment, and the body keeps that motion as velocity (v += impulse / m,
/// L += moment, w = I^-1(q') L). Static bodies (com.w == 0) are left untouched.
MOTES_FN void body_apply_position(MOTES_INOUT(vec4) com, MOTES_INOUT(vec4) quat, vec4 inv_inertia,
                                  MOTES_INOUT(vec4) vel, MOTES_INOUT(vec4) angmom,
                                  MOTES_OUT(vec4) angvel, vec3 impulse, vec3 moment, float h) {
  float inv_m = com.w;
  if (inv_m == 0.0f) {
    angvel = vec4(body_angular_velocity(quat, inv_inertia, xyz(angmom)), 0.0f);
    return;
  }
  vec3 dv = impulse * inv_m;
  com = vec4(xyz(com) + dv * h, inv_m);
  if (moment.x != 0.0f || moment.y != 0.0f || moment.z != 0.0f) {
    quat = quat_integrate(quat, body_angular_velocity(quat, inv_inertia, moment), h);
  }
  vec3 l = xyz(angmom) + moment;
  vel = vec4(xyz(vel) + dv, 0.0f);
  angmom = vec4(l, 0.0f);
  angvel = vec4(body_angular_velocity(quat, inv_inertia, l), 0.0f);
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_POSITION_H
