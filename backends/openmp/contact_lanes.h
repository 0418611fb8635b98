// Blocks of impulse contacts in lanes for impulses_sweep.cpp: each field of a contact (what its
// frame is made from, the frame, what its two bodies hold fixed through a substep, their
// velocities, its accumulated impulse and result) is an array with one lane per contact, so that
// making the frames, their responses and every pass's solve are loops of the shared functions
// (shared::contact_frame, contact_frame_response, contact_solve) over the lanes that the compiler
// puts in vector registers: their branches are plain blocks of arithmetic it computes on both
// sides and chooses between, and the flags are constants here. The arithmetic is the shared
// functions', lane by lane: the same bits as evaluating the contacts one at a time.
// docs/architecture.md, "Impulse contacts", says what the passes do; docs/benchmarks.md what the
// lanes gained.
#ifndef MOTES_OPENMP_CONTACT_LANES_H
#define MOTES_OPENMP_CONTACT_LANES_H

#include <cstdint>

#include "shared/impulse.h"

namespace motes::openmp {

/// Contacts per block: two SSE vectors, one AVX vector.
inline constexpr int kContactLanes = 8;

struct ContactBlock {
  using Lane = float[kContactLanes];
  Lane frame[20];    // shared::ContactFrame: ra, rb, n, target, response, component by component
                     // (before contact_block_frame: the normal, separation and r_a + r_b where
                     // the frame keeps them)
  Lane point[3];     // the contact point
  Lane com[2][3];    // bodies a and b: centres
  Lane restitution;  // the contact law's e
  Lane friction;     // and mu
  Lane body[2][8];   // bodies a and b: inverse mass, inverse inertia (xx yy zz xy xz yz), contacts
  Lane vel[2][6];    // bodies a and b: velocity and angular velocity, at the substep's start
                     // until the frames are made, then now (each sweep)
  Lane acc[4];       // accumulated impulse: in before a pass, out after it
  Lane result[4];    // the change of the impulse on body a (w: counted)
  std::int32_t bodies[2][kContactLanes];  // bodies a and b (the body count: a plane)
};

inline void contact_lane_put(ContactBlock::Lane* v, int l, const shared::vec4& x) {
  v[0][l] = x.x;
  v[1][l] = x.y;
  v[2][l] = x.z;
  v[3][l] = x.w;
}

inline void contact_lane_put3(ContactBlock::Lane* v, int l, const shared::vec3& x) {
  v[0][l] = x.x;
  v[1][l] = x.y;
  v[2][l] = x.z;
}

inline shared::vec4 contact_lane_vec4(const ContactBlock::Lane* v, int l) {
  return shared::vec4(v[0][l], v[1][l], v[2][l], v[3][l]);
}

inline shared::vec3 contact_lane_vec3(const ContactBlock::Lane* v, int l) {
  return shared::vec3(v[0][l], v[1][l], v[2][l]);
}

/// Lane l's side s takes body o's velocity and angular velocity at the substep's start. Field by
/// field, here and below: a local array of the parts would be stored as floats and read back as
/// vectors, a stall each.
inline void contact_lane_start_velocities(ContactBlock& k, int l, int s,
                                          const shared::ImpulseBody& o) {
  const shared::vec4& v = o.vel0;
  const shared::vec4& w = o.angvel0;
  ContactBlock::Lane* vel = k.vel[s];
  vel[0][l] = v.x;
  vel[1][l] = v.y;
  vel[2][l] = v.z;
  vel[3][l] = w.x;
  vel[4][l] = w.y;
  vel[5][l] = w.z;
}

/// Lane l takes a contact of bodies a and b (their indices ia and ib, whose velocities
/// contact_block_velocities reads) at point c (normal n from b towards a, separation sep,
/// r_a + r_b = rsum), the contact law's e and mu, and its accumulated impulse: what
/// contact_block_frame makes its frame from.
inline void contact_lane_start(ContactBlock& k, int l, std::uint32_t ia, std::uint32_t ib,
                               const shared::vec3& c, const shared::vec3& n, float sep, float rsum,
                               const shared::ImpulseBody& a, const shared::ImpulseBody& b,
                               const shared::ContactLaw& law, const shared::vec4& acc) {
  k.bodies[0][l] = std::int32_t(ia);
  k.bodies[1][l] = std::int32_t(ib);
  contact_lane_put(k.frame + 8, l, shared::vec4(n, 0.0f));
  k.frame[3][l] = sep;
  k.frame[7][l] = rsum;
  contact_lane_put3(k.point, l, c);
  contact_lane_put3(k.com[0], l, shared::xyz(a.com));
  contact_lane_put3(k.com[1], l, shared::xyz(b.com));
  k.body[0][0][l] = a.com.w;  // what contact_frame reads of them (contact_lane_bodies: the rest)
  k.body[1][0][l] = b.com.w;
  contact_lane_start_velocities(k, l, 0, a);
  contact_lane_start_velocities(k, l, 1, b);
  k.restitution[l] = law.restitution;
  k.friction[l] = law.friction;
  contact_lane_put(k.acc, l, acc);
}

/// Lane l takes no contact (a block's lanes past the last contact): zeros, no response, nothing
/// solved there.
inline void contact_lane_clear(ContactBlock& k, int l) {
  contact_lane_start(k, l, 0u, 0u, shared::vec3(0.0f), shared::vec3(0.0f), 0.0f, 0.0f,
                     shared::impulse_wall(), shared::impulse_wall(), shared::ContactLaw{},
                     shared::vec4(0.0f));
  for (auto& side : k.body) {
    for (auto& f : side) f[l] = 0.0f;
  }
}

/// Lane l takes what its bodies a and b hold through the substep's sweeps (once the counting
/// pass has counted their contacts).
inline void contact_lane_bodies(ContactBlock& k, int l, const shared::ImpulseBody& a,
                                const shared::ImpulseBody& b) {
  for (int s = 0; s < 2; ++s) {
    const shared::ImpulseBody& o = s == 0 ? a : b;
    ContactBlock::Lane* body = k.body[s];
    body[0][l] = o.com.w;
    body[1][l] = o.inv_diag.x;
    body[2][l] = o.inv_diag.y;
    body[3][l] = o.inv_diag.z;
    body[4][l] = o.inv_off.x;
    body[5][l] = o.inv_off.y;
    body[6][l] = o.inv_off.z;
    body[7][l] = o.vel0.w;
  }
}

/// Makes every lane's shared::ContactFrame (its response zero) from what contact_lane_start put
/// there.
void contact_block_frame(ContactBlock& k, shared::vec4 gravity_dt);

/// Adds every lane's response (shared::contact_frame_response; contact_lane_bodies first).
void contact_block_respond(ContactBlock& k);

/// Every lane's bodies' velocities now, from the bodies' velocity (vel[0..2]) and angular
/// velocity (vel[3..5]) components, one array each (a sweep's start).
void contact_block_velocities(ContactBlock& k, const float* const vel[6]);

/// One pass of shared::contact_solve over the block's lanes under flags (the counting pass or a
/// sweep; the velocities of a sweep put there first): new accumulated impulses and results.
void contact_block_solve(ContactBlock& k, shared::uint flags);

}  // namespace motes::openmp

#endif  // MOTES_OPENMP_CONTACT_LANES_H
