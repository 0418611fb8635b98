// Impulse-based rigid contact (Guendelman, Bridson, Fedkiw 2003, as Ponce Atencio & Esperanca use
// it for bodies made of particles): at the contact point c of two touching particles (their
// midpoint; for a plane, the particle's lowest point), an impulse J acts on the two bodies,
//   v' = v + J / m,   L' = L + (c - x_com) x J,
// with restitution e and Coulomb friction mu. The many particle contacts of one body pair act
// together through mass splitting (Tonge, Benevolenski, Voroshilov 2012): every contact of a body
// that has n contacts sees the body with n times its inverse mass and inverse inertia, all
// contacts are solved at once (Jacobi) and a body's impulses are summed in a fixed order, so the
// body's velocity is the average of what each contact asks for. Each contact keeps its
// accumulated impulse (clamped as a total, never per iteration) and starts every substep from the
// last one's (warm start; Catto's accumulated impulses), so a resting stack carries its weight
// from the first iteration. Iterated a fixed number of times per substep, this converges to the
// simultaneous solution; it needs no atomics and no order that depends on thread timing.
// docs/architecture.md, "Impulse contacts", has the whole stage.
#ifndef MOTES_SHARED_IMPULSE_H
#define MOTES_SHARED_IMPULSE_H

#include "body_math.h"
#include "common.h"
#include "contact_body.h"
#include "contact_gram.h"
#include "params.h"
#include "position.h"

MOTES_SHARED_BEGIN

/// Position correction of an overlapping contact (beyond the slop) as a soft constraint (Catto's
/// "soft step", Box2D v3): a spring-damper at a quarter of the substep rate (omega h = pi / 2),
/// damping ratio zeta = 10, solved implicitly. With a1 = 2 zeta + omega h, a2 = omega h a1,
/// a3 = 1 / (1 + a2): the contact asks for a separating speed of MOTES_IMPULSE_BIAS of the overlap
/// per substep (omega h / a1), weighs its velocity error by MOTES_IMPULSE_MASS_SCALE (a2 a3) and
/// gives back MOTES_IMPULSE_LEAK (a3) of its accumulated normal impulse per sweep. The leak keeps
/// the impulse of a body wedged between two others bounded (rigid targets that cannot all be met
/// would make it grow without end, sweep after sweep, substep after substep). Split impulses'
/// correcting sweeps (MOTES_FLAG_IMPULSE_SPLIT) do not leak: their impulses are forgotten at the
/// substep's end, so they cannot grow across substeps, and with the leak, which takes support
/// from every resting contact, columns of offset boxes crept (openmp: 2 of 50 seeds drifted over
/// 1% of a diameter, 1 without it; on an H200, 65 and 63 of 500 on CUDA and Vulkan, 37 and 33) and
/// the impulse domino window's velocities after one step agreed across backends 8 times worse
/// (lavapipe against openmp: 1.3e-5 m/s, 1.7e-6 without).
#define MOTES_IMPULSE_BIAS 0.0728205f
#define MOTES_IMPULSE_MASS_SCALE 0.9713330f
#define MOTES_IMPULSE_LEAK 0.0286670f
/// The most an overlap is corrected per substep, as a fraction of r_a + r_b.
#define MOTES_IMPULSE_PUSH_MAX 0.005f
/// Overlap left alone, as a fraction of r_a + r_b: resting contacts keep it without jitter.
#define MOTES_IMPULSE_SLOP 0.002f
/// A contact closing faster than this many substeps' worth of gravity bounces (restitution);
/// slower ones (resting contacts, which close at |g| dt every substep) do not.
#define MOTES_IMPULSE_BOUNCE_SUBSTEPS 4.0f

/// Contacts reach this far apart (speculative contacts), as a fraction of the neighbour skin:
/// every pair this close is in the lists since their last build (two particles close at most
/// 2 x 0.45 skin before a rebuild), so the contact set does not depend on when lists were built.
MOTES_FN float impulse_margin(float skin) { return 0.1f * skin; }

/// The normal velocity (separating > 0) a contact must reach in this substep, from its
/// separation sep (< 0: overlap) and its normal velocity vn0 at the start of the substep:
/// - apart (sep > 0): approach by at most the gap (speculative contact: touch, don't pass);
/// - overlapping, in the sweeps with position correction: separate at MOTES_IMPULSE_BIAS of the
///   overlap beyond the slop per substep (at most MOTES_IMPULSE_PUSH_MAX of r_a + r_b); in the
///   relaxing sweeps (MOTES_FLAG_IMPULSE_RELAX): 0, so the speed of that correction moves the
///   pose but is not kept;
/// - closing faster than resting contacts do, with e > 0: bounce at -e vn0 (Newton's law).
/// soft: 1 in the sweeps with position correction unless the contact bounces, apart or not (the
/// soft step's scale and leak then do not switch as a resting contact's gap crosses 0, where two
/// backends' roundings of sep would otherwise part their trajectories), else 0.
MOTES_FN float impulse_target(float sep, float rsum, float vn0, float restitution, vec4 gravity_dt,
                              uint flags, MOTES_OUT(float) soft) {
  // Every case computed, the one that holds chosen: the openmp backend makes frames in vector
  // lanes (contact_lanes.cpp), and nested branches here would keep it from doing so.
  float dt = gravity_dt.w;
  bool relax = (flags & MOTES_FLAG_IMPULSE_RELAX) != 0u;
  float overlap = max(-sep - MOTES_IMPULSE_SLOP * rsum, 0.0f);
  float push = relax ? 0.0f : min(MOTES_IMPULSE_BIAS * overlap, MOTES_IMPULSE_PUSH_MAX * rsum) / dt;
  float target = sep <= 0.0f ? push : -sep / dt;
  float bounce_speed = MOTES_IMPULSE_BOUNCE_SUBSTEPS * length(xyz(gravity_dt)) * dt;
  float bounce = -restitution * vn0;
  bool closing = restitution > 0.0f && vn0 < -bounce_speed && vn0 * dt < -sep;
  bool bounces = closing && bounce > target;
  soft = relax || bounces ? 0.0f : 1.0f;
  return bounces ? bounce : target;
}

/// What the sweeps of one substep do not change in a contact between bodies a and b at point c
/// (contact_impulse): poses and the velocities at the substep's start are fixed until the pose.
struct ContactFrame {
  vec4 ra;        // xyz: arm on a (c - a's centre), w: separation (< 0: overlap)
  vec4 rb;        // xyz: arm on b, w: r_a + r_b
  vec4 n;         // xyz: unit normal from b towards a, w: normal velocity at the substep's start
  vec4 target;    // impulse_target and its soft flag in the correcting sweeps (and the counting
                  // pass): x, y; the target of the relaxing ones (MOTES_FLAG_IMPULSE_RELAX, never
                  // soft): z; w: the stack scale (contact_stack_scale)
  vec4 response;  // xyz: the contact's response to a unit normal impulse, w: its normal part
};

/// The stack scale of a contact between bodies a and b (position_stack_scale: negative when a is
/// the lower body, positive when b is, 1 for none): the lower body of a resting contact between
/// two dynamic bodies counts as heavier in every pass of the substep, as position contacts do
/// (docs/architecture.md, "Impulse contacts": why a column of offset boxes needs it); 1 when
/// either body is static.
MOTES_FN float contact_stack_scale(MOTES_IN(ImpulseBody) a, MOTES_IN(ImpulseBody) b, float rsum,
                                   float vn0, vec4 gravity_dt) {
  // Continuous in vn0: the full scale up to the bounce speed, none from twice it, linear between
  // (a jump at one speed is a decision two backends' roundings can take apart).
  bool on = a.com.w != 0.0f && b.com.w != 0.0f;
  float g = length(xyz(gravity_dt));
  float bounce = MOTES_IMPULSE_BOUNCE_SUBSTEPS * g * gravity_dt.w;
  float s = stack_height_scale(xyz(a.com), xyz(b.com), rsum, g, gravity_dt);
  float w = g > 0.0f ? clamp((vn0 + 2.0f * bounce) / max(bounce, 1e-30f), 0.0f, 1.0f) : 0.0f;
  float fw = 1.0f + w * (abs(s) - 1.0f);
  return on ? (s > 0.0f ? fw : -fw) : 1.0f;
}

/// A contact's impulse r on side a (side_b false) or, negated, on side b, each scaled by its share
/// (stack_side_scale of the contact's stack scale s); w is kept.
MOTES_FN vec4 contact_side_impulse(vec4 r, float s, bool side_b) {
  float k = side_b ? -stack_side_scale(s, true) : stack_side_scale(s, false);
  return vec4(r.x * k, r.y * k, r.z * k, r.w);
}

/// A contact's frame before its response is known (contact_frame_response: the bodies' contact
/// counts, which scale it, are known only after the counting pass).
MOTES_FN ContactFrame contact_frame(MOTES_IN(ImpulseBody) a, MOTES_IN(ImpulseBody) b, vec3 c,
                                    vec3 n, float sep, float rsum, float restitution,
                                    vec4 gravity_dt) {
  ContactFrame f;
  vec3 ra = c - xyz(a.com);
  vec3 rb = c - xyz(b.com);
  vec3 u0 =
      impulse_point_velocity(a.vel0, a.angvel0, ra) - impulse_point_velocity(b.vel0, b.angvel0, rb);
  float vn0 = dot(u0, n);
  f.ra = vec4(ra, sep);
  f.rb = vec4(rb, rsum);
  f.n = vec4(n, vn0);
  float soft = 0.0f;
  float relax_soft = 0.0f;  // 0 whatever it was: relaxing sweeps are never soft
  float target = impulse_target(sep, rsum, vn0, restitution, gravity_dt, 0u, soft);
  float relax_target =
      impulse_target(sep, rsum, vn0, restitution, gravity_dt, MOTES_FLAG_IMPULSE_RELAX, relax_soft);
  f.target = vec4(target, soft, relax_target, contact_stack_scale(a, b, rsum, vn0, gravity_dt));
  f.response = vec4(0.0f);
  return f;
}

/// The change of the relative velocity at the contact that a unit normal impulse makes (both
/// bodies' impulse_response), and its normal part kn.
MOTES_FN void contact_frame_response(MOTES_INOUT(ContactFrame) f, MOTES_IN(ImpulseBody) a,
                                     MOTES_IN(ImpulseBody) b) {
  vec3 n = xyz(f.n);
  vec3 response = impulse_response(a, xyz(f.ra), n) * stack_side_scale(f.target.w, false) +
                  impulse_response(b, xyz(f.rb), n) * stack_side_scale(f.target.w, true);
  f.response = vec4(response, dot(response, n));
}

/// contact_impulse from the contact's frame f (its response filled unless counting), with the
/// bodies' velocities now in a and b. Its branches are plain blocks of arithmetic and its
/// early outs choices (shared/common.h, choose), so that the openmp backend's loop over a block of
/// contacts runs in vector lanes (contact_lanes.cpp: both sides computed, the one taken chosen,
/// the same bits), while a GPU may still skip a block its threads do not take.
MOTES_FN vec4 contact_solve(MOTES_IN(ImpulseBody) a, MOTES_IN(ImpulseBody) b,
                            MOTES_IN(ContactFrame) f, ContactLaw law, uint flags,
                            MOTES_INOUT(vec4) acc) {
  vec3 ra = xyz(f.ra);
  vec3 rb = xyz(f.rb);
  vec3 n = xyz(f.n);
  float sep = f.ra.w;
  float vn0 = f.n.w;
  bool relaxing = (flags & MOTES_FLAG_IMPULSE_RELAX) != 0u;
  bool counting = (flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  float target = relaxing ? f.target.z : f.target.x;
  float soft = relaxing ? 0.0f : f.target.y;
  float counts = 1.0f;
  vec3 old_total = xyz(acc);
  float jn = acc.w;
  vec3 jt = old_total - n * dot(old_total, n);
  // A contact without a response (both sides static) is left as it is.
  bool solved = counting || f.response.w > 0.0f;
  if (counting) {
    jn = sep > 0.0f && target <= vn0 ? 0.0f : jn;
  } else {
    vec3 u =
        impulse_point_velocity(a.vel, a.angvel, ra) - impulse_point_velocity(b.vel, b.angvel, rb);
    float vn = dot(u, n);
    vec3 response = xyz(f.response);
    float kn = f.response.w;
    float scale = soft > 0.0f ? MOTES_IMPULSE_MASS_SCALE : 1.0f;
    bool leaks = soft > 0.0f && (flags & MOTES_FLAG_IMPULSE_SPLIT) == 0u;
    float leak = leaks ? MOTES_IMPULSE_LEAK : 0.0f;
    float jn_new = max(jn + scale * (target - vn) / kn - leak * jn, 0.0f);
    // Friction sees the velocity the normal impulse leaves.
    u += response * (jn_new - jn);
    jn = jn_new;
    vec3 vt = u - n * dot(u, n);
    float vt2 = dot(vt, vt);
    if (vt2 > 0.0f && law.friction != 0.0f) {
      float vt_len = sqrt(vt2);
      vec3 t = vt / vt_len;
      float kt = impulse_inverse_mass(a, ra, t) * stack_side_scale(f.target.w, false) +
                 impulse_inverse_mass(b, rb, t) * stack_side_scale(f.target.w, true);
      jt -= t * (vt_len / kt);
    }
  }
  float cap = law.friction * jn;
  float jt2 = dot(jt, jt);
  if (law.friction > 0.0f && jt2 > cap * cap) {  // a branch a GPU may skip; lanes take both
    jt = jt * (cap / sqrt(jt2));
  }
  jt = choose(law.friction == 0.0f, vec3(0.0f), jt);
  jt = choose(jn == 0.0f, vec3(0.0f), jt);
  vec3 total = n * jn + jt;
  // The counting pass applies the whole warm start: nothing of this substep is applied yet.
  vec3 applied = counting ? vec3(0.0f) : old_total;
  acc = choose(solved, vec4(total, jn), acc);
  return choose(solved, vec4(total - applied, counts), vec4(0.0f, 0.0f, 0.0f, counts));
}

/// The impulse on body a of a contact between bodies a and b at point c, normal n (unit, from b
/// towards a), separation sep, r_a + r_b = rsum (on b: its negation), as a change of the contact's
/// accumulated impulse acc (xyz: the total impulse on a in this substep; w: its normal part, >= 0).
/// Returns (the change, counted): every contact within reach counts for mass splitting (1), so a
/// body is never seen lighter than its contacts can make it (fewer would let the sweeps overshoot,
/// and grow, as soon as a contact that was apart at the count starts to push).
/// - Counting pass (MOTES_FLAG_IMPULSE_COUNT): warm start. A contact that touches or needs an
///   impulse at the start of the substep starts from the total of the last substep (acc), its
///   tangential part capped at mu times its normal part; one that does not starts from zero.
/// - Sweeps: the normal total grows by what brings the normal velocity to impulse_target (soft
///   where impulse_target says so) and is clamped at zero (a contact pushes, never pulls, but may
///   take back what it pushed too much); then, from the velocity that leaves (the contact solved
///   as one block), the tangential total grows by what stops the sliding at c and is capped at mu
///   times the normal total (law.friction < 0: no cap; 0: none). Only totals are clamped, so the
///   sweeps converge to the simultaneous solution (projected Gauss-Seidel's rule, applied
///   Jacobi-style).
/// With acc = 0 on entry every time (a contact without a slot), this is the plain impulse. It is
/// contact_frame, contact_frame_response and contact_solve: a backend that keeps the frames of a
/// substep's contacts (openmp) solves each sweep from them, with the same bits.
MOTES_FN vec4 contact_impulse(MOTES_IN(ImpulseBody) a, MOTES_IN(ImpulseBody) b, vec3 c, vec3 n,
                              float sep, float rsum, ContactLaw law, vec4 gravity_dt, uint flags,
                              MOTES_INOUT(vec4) acc, MOTES_OUT(float) stack) {
  ContactFrame f = contact_frame(a, b, c, n, sep, rsum, law.restitution, gravity_dt);
  stack = f.target.w;
  if ((flags & MOTES_FLAG_IMPULSE_COUNT) == 0u) {
    contact_frame_response(f, a, b);
  }
  return contact_solve(a, b, f, law, flags, acc);
}

/// True when particles xa and xb (w: radii) are within reach of a contact: their gap below margin
/// (impulse_margin) and their centres apart.
MOTES_FN bool pair_within_reach(vec4 xa, vec4 xb, float margin) {
  vec3 d = xyz(xa) - xyz(xb);
  float dist2 = dot(d, d);
  float reach = xa.w + xb.w + margin;
  return !(dist2 >= reach * reach || dist2 == 0.0f);
}

/// The impulse on body a of particle a (centre xa, radius ra) touching particle b, as a change of
/// the contact's accumulated impulse acc (contact_impulse). The pair is always evaluated in the
/// order (lower particle id first), so that the two particles of a contact compute bitwise
/// opposite impulses and bitwise equal totals: call with a = the lower id and negate for b.
/// Zero (not counted, acc zeroed) when their gap is margin (impulse_margin) or more, or their
/// centres coincide.
MOTES_FN vec4 particle_contact_impulse(MOTES_IN(ImpulseBody) a, vec4 xa, MOTES_IN(ImpulseBody) b,
                                       vec4 xb, float margin, ContactLaw law, vec4 gravity_dt,
                                       uint flags, MOTES_INOUT(vec4) acc, MOTES_OUT(float) stack) {
  stack = 1.0f;
  if (!pair_within_reach(xa, xb, margin)) {
    acc = vec4(0.0f);  // zero already in the iterations: positions do not change within them
    return vec4(0.0f);
  }
  vec3 d = xyz(xa) - xyz(xb);
  float rsum = xa.w + xb.w;
  float dist = sqrt(dot(d, d));
  return contact_impulse(a, b, pair_contact_point(xa, xb), d / dist, dist - rsum, rsum, law,
                         gravity_dt, flags, acc, stack);
}

/// The position contact (shared/position.h: contact_position) of particle a (centre xa, radius
/// ra, body a) and particle b, evaluated as particle_contact_impulse is (a: the lower id), with
/// rel = x_a - x_b. No contact (zeros, acc zeroed) when their gap is margin or more, or their
/// centres coincide.
MOTES_FN PositionPair particle_contact_position(MOTES_IN(ImpulseBody) a, vec4 xa,
                                                MOTES_IN(ImpulseBody) b, vec4 xb, float margin,
                                                ContactLaw law, vec4 gravity_dt, uint flags,
                                                MOTES_INOUT(vec4) acc) {
  vec3 d = xyz(xa) - xyz(xb);
  float dist2 = dot(d, d);
  float rsum = xa.w + xb.w;
  float reach = rsum + margin;
  if (dist2 >= reach * reach || dist2 == 0.0f) {
    PositionPair none;
    none.a = vec4(0.0f);
    none.b = vec4(0.0f);
    acc = vec4(0.0f);
    return none;
  }
  float dist = sqrt(dist2);
  return contact_position(a, b, xyz(xa), xyz(xb), d / dist, dist - rsum, rsum, d, law, gravity_dt,
                          flags, acc);
}

/// Index in the contact-law table of the pair of particles i and j (materials mi, mj) as
/// pair_impulse evaluates it: the lower id's material first, so both particles use one law.
MOTES_FN uint pair_law_index(uint i, uint mi, uint j, uint mj, uint materials) {
  return i < j ? mi * materials + mj : mj * materials + mi;
}

/// A rigid particle as impulse contacts take it (w: its radius): its offset from its body's
/// centre, R local, not its position. A pair's geometry is then the difference of the bodies'
/// centres (exact for bodies nearer each other than to the origin) and of two small offsets, as
/// precise far from the origin as near it. Positions 50 m out are 3.8 um apart in float, a fifth
/// of the slop, and rounding each particle's position on its own made resting chains and piles
/// creep there (docs/architecture.md, "Impulse contacts"). Position contacts
/// (MOTES_FLAG_POSITION), whose sweeps read positions that the poses have not made, take the
/// position.
MOTES_FN vec4 contact_particle(vec4 pos, vec4 quat, vec4 local, uint flags) {
  return (flags & MOTES_FLAG_POSITION) != 0u ? pos : vec4(quat_rotate(quat, xyz(local)), pos.w);
}

/// A body as the impulse contacts of one of its particles (contact_particle) see it: its centre at
/// the origin. Position contacts: as it is.
MOTES_FN ImpulseBody contact_body(MOTES_IN(ImpulseBody) b, uint flags) {
  ImpulseBody o = b;
  if ((flags & MOTES_FLAG_POSITION) == 0u) o.com = vec4(0.0f, 0.0f, 0.0f, b.com.w);
  return o;
}

/// A pair of rigid particles as particle_contact_impulse evaluates it: the lower id first (a).
struct ContactPair {
  ImpulseBody a;
  ImpulseBody b;
  vec4 xa;
  vec4 xb;
};

/// contact_pair's particles alone (xa, xb), from their bodies' centres own_com and other_com: what
/// a test of the pair's reach needs (pair_within_reach), the same bits.
MOTES_FN void pair_places(vec4 own_com, vec4 xi, vec4 other_com, vec4 xj, bool own_first,
                          uint flags, MOTES_OUT(vec4) xa, MOTES_OUT(vec4) xb) {
  xa = own_first ? xi : xj;
  xb = own_first ? xj : xi;
  if ((flags & MOTES_FLAG_POSITION) == 0u) {
    vec3 shift = own_first ? xyz(other_com) - xyz(own_com) : xyz(own_com) - xyz(other_com);
    xb = vec4(shift + xyz(xb), xb.w);
  }
}

/// Particle xi of body own and xj of body other (contact_particle), the lower id first (own_first:
/// xi's), placed for impulse contacts with a's centre at the origin: xa its offset, b's centre at
/// com_b - com_a and xb there plus its offset. Both particles of the pair make the same bits.
MOTES_FN ContactPair contact_pair(MOTES_IN(ImpulseBody) own, vec4 xi, MOTES_IN(ImpulseBody) other,
                                  vec4 xj, bool own_first, uint flags) {
  ContactPair pr;
  if (own_first) {
    pr.a = own;
    pr.b = other;
  } else {
    pr.a = other;
    pr.b = own;
  }
  pair_places(own.com, xi, other.com, xj, own_first, flags, pr.xa, pr.xb);
  if ((flags & MOTES_FLAG_POSITION) == 0u) {
    pr.b.com = vec4(xyz(pr.b.com) - xyz(pr.a.com), pr.b.com.w);
    pr.a.com = vec4(0.0f, 0.0f, 0.0f, pr.a.com.w);
  }
  return pr;
}

/// Where the contact of a pair (contact_pair) acts on its particle of the lower id's side (side_b
/// false) or the other's, about that side's centre (contact_acting_point).
MOTES_FN vec3 pair_contact_arm(MOTES_IN(ContactPair) pr, bool side_b, uint flags) {
  vec3 c = pair_contact_point(pr.xa, pr.xb);
  return side_b ? contact_acting_point(c, pr.xb, flags) - xyz(pr.b.com)
                : contact_acting_point(c, pr.xa, flags) - xyz(pr.a.com);
}

/// pair_impulse's impulse contact, both sides at once: the impulse on body `own` returned, the one
/// on body `other` in other_side (the openmp sweeps evaluate a contact once for both particles).
/// Each is its side's share of the contact's impulse (contact_stack_scale: the lower body's is
/// less).
MOTES_FN vec4 pair_impulse_sides(MOTES_IN(ImpulseBody) own, vec4 xi, MOTES_IN(ImpulseBody) other,
                                 vec4 xj, bool own_first, float margin, ContactLaw law,
                                 vec4 gravity_dt, uint flags, MOTES_INOUT(vec4) acc,
                                 MOTES_OUT(vec4) other_side) {
  float stack = 1.0f;
  ContactPair pr = contact_pair(own, xi, other, xj, own_first, flags);
  vec4 r = particle_contact_impulse(pr.a, pr.xa, pr.b, pr.xb, margin, law, gravity_dt, flags, acc,
                                    stack);
  vec4 on_a = contact_side_impulse(r, stack, false);  // the lower id's side
  vec4 on_b = contact_side_impulse(r, stack, true);
  other_side = own_first ? on_b : on_a;
  return own_first ? on_a : on_b;
}

/// The impulse on body `own` (w: counted) of its particle xi and particle xj of body `other` (both
/// as contact_particle gives them); own_first: xi has the lower particle id (see
/// particle_contact_impulse). acc: the contact's accumulated impulse, as the lower id sees it (the
/// same bits in both particles' slots). arm: where it acts on own, from own's centre
/// (pair_contact_arm).
MOTES_FN vec4 pair_impulse(MOTES_IN(ImpulseBody) own, vec4 xi, MOTES_IN(ImpulseBody) other, vec4 xj,
                           bool own_first, float margin, ContactLaw law, vec4 gravity_dt,
                           uint flags, MOTES_INOUT(vec4) acc, MOTES_OUT(vec3) arm) {
  arm = pair_contact_arm(contact_pair(own, xi, other, xj, own_first, flags), !own_first, flags);
  if ((flags & MOTES_FLAG_POSITION) != 0u) {  // the same evaluation, each side its own result
    PositionPair r =
        own_first
            ? particle_contact_position(own, xi, other, xj, margin, law, gravity_dt, flags, acc)
            : particle_contact_position(other, xj, own, xi, margin, law, gravity_dt, flags, acc);
    return own_first ? r.a : r.b;
  }
  vec4 other_side;
  return pair_impulse_sides(own, xi, other, xj, own_first, margin, law, gravity_dt, flags, acc,
                            other_side);
}

/// A plane (normal, offset) as the impulse contacts of a particle of body b (contact_particle) see
/// it: offset by b's centre. Position contacts: as it is.
MOTES_FN vec4 contact_plane(vec4 normal_offset, MOTES_IN(ImpulseBody) b, uint flags) {
  if ((flags & MOTES_FLAG_POSITION) != 0u) return normal_offset;
  return vec4(xyz(normal_offset), normal_offset.w - dot(xyz(normal_offset), xyz(b.com)));
}

/// Where the contact of particle xa (contact_particle) of body a and a plane acts on it, about a's
/// centre (contact_acting_point).
MOTES_FN vec3 plane_contact_arm(MOTES_IN(ImpulseBody) a, vec4 xa, vec4 normal_offset, uint flags) {
  ImpulseBody o = contact_body(a, flags);
  vec4 no = contact_plane(normal_offset, a, flags);
  return contact_acting_point(plane_contact_point(xa, no), xa, flags) - xyz(o.com);
}

/// The impulse on body a of its particle xa and a static half-space plane (solid where
/// dot(normal, x) < offset), at the particle's point nearest the plane, as a change of the
/// contact's accumulated impulse acc (contact_impulse); xa as contact_particle gives it. arm:
/// where it acts, from a's centre (plane_contact_arm).
MOTES_FN vec4 plane_contact_impulse(MOTES_IN(ImpulseBody) a, vec4 xa, vec4 normal_offset,
                                    float margin, ContactLaw law, vec4 gravity_dt, uint flags,
                                    MOTES_INOUT(vec4) acc, MOTES_OUT(vec3) arm) {
  arm = plane_contact_arm(a, xa, normal_offset, flags);
  ImpulseBody o = contact_body(a, flags);
  vec4 no = contact_plane(normal_offset, a, flags);
  vec3 np = xyz(no);
  float sep = dot(np, xyz(xa)) - no.w - xa.w;
  if (sep >= margin) {
    acc = vec4(0.0f);  // zero already in the iterations: positions do not change within them
    return vec4(0.0f);
  }
  vec3 c = plane_contact_point(xa, no);
  if ((flags & MOTES_FLAG_POSITION) != 0u) {
    return contact_position(o, impulse_wall(), xyz(xa), c, np, sep, 2.0f * xa.w,
                            plane_contact_rel(c, np), law, gravity_dt, flags, acc)
        .a;
  }
  float stack = 1.0f;  // a wall: never scaled
  return contact_impulse(o, impulse_wall(), c, np, sep, xa.w, law, gravity_dt, flags, acc, stack);
}

/// True when the contact of particles i and j (neighbour counts ci and cj) keeps its accumulated
/// impulse in both particles' list slots: both lists hold all their neighbours (capacity K). A
/// particle beyond K walks the grid and has no slots, so both sides solve that contact without
/// memory (acc = 0 each time), and stay bitwise opposite.
MOTES_FN bool impulse_pair_slotted(uint ci, uint cj, uint capacity) {
  return ci <= capacity && cj <= capacity;
}

/// True when the contact of particle i (stamp si) and particle j (stamp sj; static: its inverse
/// mass vj_inv_mass is 0) may start from its accumulated impulse at the counting pass of build
/// `builds`: both particles' slots were written under this build, or under the last one with the
/// same list (neighbour_keeps_slots moved their stamp on). Both particles of a pair decide alike,
/// so their slots keep holding the same bits. A static particle evaluates no contact (no list):
/// only i's side counts then.
MOTES_FN bool impulse_slots_valid(uint si, uint sj, float vj_inv_mass, uint builds) {
  return si == builds && (vj_inv_mass == 0.0f || sj == builds);
}

/// neighbours_build, for a rigid particle whose slots were valid under the last build (its stamp
/// equals that build's count): true when its new list is the old one, entry for entry (the same
/// count, the same particles in the same order), so its slots still name the same contacts and
/// its stamp moves on to the new build. A particle near nothing that moved keeps its list: a
/// rebuild that something far away asked for does not cost a resting stack its memory.
MOTES_FN bool neighbour_keeps_slots(uint old_count, uint new_count, bool same_entries,
                                    uint capacity) {
  return old_count == new_count && new_count <= capacity && same_entries;
}

/// Adds a contact's impulse r (w: counted) acting at arm from the body's centre to a particle's
/// sums: the impulse and count (sum), the moment about the body's centre (moment). With
/// MOTES_FLAG_POSITION_GRAM, r.xyz is the contact's normal n: sum.xyz gains the diagonal of
/// n n^T and moment the rest (xy, xz, yz; shared/contact_gram.h).
MOTES_FN void impulse_add(MOTES_INOUT(vec4) sum, MOTES_INOUT(vec3) moment, vec4 r, vec3 arm,
                          uint flags) {
  if ((flags & MOTES_FLAG_POSITION_GRAM) != 0u) {
    sum = sum + vec4(r.x * r.x, r.y * r.y, r.z * r.z, r.w);
    moment += vec3(r.x * r.y, r.x * r.z, r.y * r.z);
    return;
  }
  sum = sum + r;
  moment += cross(arm, xyz(r));
}

/// impulses_apply sums a body's particles in chunks of this many, counted from its first
/// particle: each chunk in particle order from zero, then the chunks' sums in chunk order from
/// zero (for a body of up to MOTES_BODY_CHUNK particles, plain particle order). A GPU sums the
/// chunks of a large body side by side and adds them in turn (a rigid bunny of 3,000 particles
/// is 47 chunks, not 3,000 additions on one thread), and every backend makes the same bits.
#define MOTES_BODY_CHUNK 64u

/// The chunk of particle i of the body whose first particle is `first` (MOTES_BODY_CHUNK).
MOTES_FN uint body_chunk(uint i, uint first) { return (i - first) / MOTES_BODY_CHUNK; }

/// Body state at the end of an impulse iteration: v += J / m, L += tau, w = I^-1(q) L.
/// Static bodies (com.w == 0) are left untouched.
MOTES_FN void body_apply_impulse(vec4 com, vec4 quat, vec4 inv_inertia, MOTES_INOUT(vec4) vel,
                                 MOTES_INOUT(vec4) angmom, MOTES_OUT(vec4) angvel, vec3 impulse,
                                 vec3 moment) {
  float inv_m = com.w;
  if (inv_m == 0.0f) {
    angvel = vec4(body_angular_velocity(quat, inv_inertia, xyz(angmom)), 0.0f);
    return;
  }
  vec3 l = xyz(angmom) + moment;
  vel = vec4(xyz(vel) + impulse * inv_m, 0.0f);
  angmom = vec4(l, 0.0f);
  angvel = vec4(body_angular_velocity(quat, inv_inertia, l), 0.0f);
}

/// What impulses_apply does with a body's summed impulse and moment under any flags: the
/// projection of position contacts (MOTES_FLAG_POSITION without MOTES_FLAG_IMPULSE_COUNT or
/// MOTES_FLAG_POSITION_VELOCITY) moves the pose too (shared/position.h: body_apply_position);
/// everything else changes the velocities (body_apply_impulse).
MOTES_FN void body_apply_contacts(MOTES_INOUT(vec4) com, MOTES_INOUT(vec4) quat, vec4 inv_inertia,
                                  MOTES_INOUT(vec4) vel, MOTES_INOUT(vec4) angmom,
                                  MOTES_OUT(vec4) angvel, vec3 impulse, vec3 moment,
                                  vec4 gravity_dt, uint flags) {
  uint pass = MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_POSITION_VELOCITY;
  if ((flags & MOTES_FLAG_POSITION_GRAM) != 0u) {  // the sums are n n^T, not impulses
    body_apply_impulse(com, quat, inv_inertia, vel, angmom, angvel, vec3(0.0f), vec3(0.0f));
  } else if ((flags & pass) == MOTES_FLAG_POSITION) {
    body_apply_position(com, quat, inv_inertia, vel, angmom, angvel, impulse, moment, gravity_dt.w);
  } else {
    body_apply_impulse(com, quat, inv_inertia, vel, angmom, angvel, impulse, moment);
  }
}

MOTES_SHARED_END

#ifdef __cplusplus
// The openmp backend keeps these in arrays (impulses_sweep.cpp).
static_assert(sizeof(motes::shared::ImpulseBody) == 112, "ImpulseBody layout");
static_assert(sizeof(motes::shared::ContactFrame) == 80, "ContactFrame layout");
#endif

#endif  // MOTES_SHARED_IMPULSE_H
