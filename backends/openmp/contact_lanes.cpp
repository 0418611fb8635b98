// The loops over a block's lanes (contact_lanes.h): each reads a lane's contact into the shared
// structs, calls the shared function and writes its answer back, lane by lane, in a loop the
// compiler puts in vector registers (flattened, so that the shared functions are inlined into
// it). On x86-64 with GCC each loop comes twice, for SSE2 (4 lanes a vector, every x86-64) and
// for AVX2 (8 lanes), the one the CPU has chosen when the program loads. Neither contracts a
// multiply and an add (ISO C++), and both round every operation alike: the same bits.
#include "contact_lanes.h"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#include <immintrin.h>
#endif

namespace motes::openmp {

namespace {

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define MOTES_LANES gnu::target_clones("avx2", "default"), gnu::flatten
#else
#define MOTES_LANES gnu::flatten
#endif

using shared::uint;
using shared::vec3;
using shared::vec4;

/// Side s of lane l as contact_solve and contact_frame_response read a body (its centre and start
/// velocities, which they do not read, zero).
shared::ImpulseBody lane_body(const ContactBlock& k, int s, int l) {
  shared::ImpulseBody o;
  o.com = vec4(0.0f, 0.0f, 0.0f, k.body[s][0][l]);
  o.inv_diag = vec4(k.body[s][1][l], k.body[s][2][l], k.body[s][3][l], 0.0f);
  o.inv_off = vec4(k.body[s][4][l], k.body[s][5][l], k.body[s][6][l], 0.0f);
  o.vel = vec4(k.vel[s][0][l], k.vel[s][1][l], k.vel[s][2][l], 0.0f);
  o.angvel = vec4(k.vel[s][3][l], k.vel[s][4][l], k.vel[s][5][l], 0.0f);
  o.vel0 = vec4(0.0f, 0.0f, 0.0f, k.body[s][7][l]);
  o.angvel0 = vec4(0.0f);
  return o;
}

/// Side s of lane l as contact_frame reads a body: its centre, inverse mass and its velocities at
/// the substep's start.
shared::ImpulseBody lane_start_body(const ContactBlock& k, int s, int l) {
  shared::ImpulseBody o = shared::impulse_wall();
  o.com = vec4(contact_lane_vec3(k.com[s], l), k.body[s][0][l]);
  o.vel0 = vec4(k.vel[s][0][l], k.vel[s][1][l], k.vel[s][2][l], 0.0f);
  o.angvel0 = vec4(k.vel[s][3][l], k.vel[s][4][l], k.vel[s][5][l], 0.0f);
  return o;
}

shared::ContactFrame lane_frame(const ContactBlock& k, int l) {
  shared::ContactFrame f;
  f.ra = contact_lane_vec4(k.frame, l);
  f.rb = contact_lane_vec4(k.frame + 4, l);
  f.n = contact_lane_vec4(k.frame + 8, l);
  f.target = contact_lane_vec4(k.frame + 12, l);
  f.response = contact_lane_vec4(k.frame + 16, l);
  return f;
}

template <uint kFlags>
[[MOTES_LANES]] void solve_lanes(ContactBlock& k) {
  for (int l = 0; l < kContactLanes; ++l) {
    const shared::ImpulseBody a = lane_body(k, 0, l);
    const shared::ImpulseBody b = lane_body(k, 1, l);
    const shared::ContactFrame f = lane_frame(k, l);
    shared::ContactLaw law{};
    law.friction = k.friction[l];
    vec4 acc = contact_lane_vec4(k.acc, l);
    const vec4 r = shared::contact_solve(a, b, f, law, kFlags, acc);
    contact_lane_put(k.acc, l, acc);
    contact_lane_put(k.result, l, r);
  }
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
/// contact_block_velocities with AVX2's gathers: eight lanes' component in one instruction (the
/// compiler does not make them from the plain loop).
[[gnu::target("avx2")]] void velocities_gathered(ContactBlock& k, const float* const vel[6]) {
  for (int s = 0; s < 2; ++s) {
    const __m256i at = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(k.bodies[s]));
    for (int f = 0; f < 6; ++f) _mm256_storeu_ps(k.vel[s][f], _mm256_i32gather_ps(vel[f], at, 4));
  }
}
#endif

}  // namespace

[[MOTES_LANES]] void contact_block_frame(ContactBlock& k, vec4 gravity_dt) {
  for (int l = 0; l < kContactLanes; ++l) {
    const shared::ContactFrame f =
        shared::contact_frame(lane_start_body(k, 0, l), lane_start_body(k, 1, l),
                              contact_lane_vec3(k.point, l), contact_lane_vec3(k.frame + 8, l),
                              k.frame[3][l], k.frame[7][l], k.restitution[l], gravity_dt);
    contact_lane_put(k.frame, l, f.ra);
    contact_lane_put(k.frame + 4, l, f.rb);
    contact_lane_put(k.frame + 8, l, f.n);
    contact_lane_put(k.frame + 12, l, f.target);
    contact_lane_put(k.frame + 16, l, f.response);
  }
}

[[MOTES_LANES]] void contact_block_respond(ContactBlock& k) {
  for (int l = 0; l < kContactLanes; ++l) {
    shared::ContactFrame f = lane_frame(k, l);
    shared::contact_frame_response(f, lane_body(k, 0, l), lane_body(k, 1, l));
    contact_lane_put(k.frame + 16, l, f.response);
  }
}

void contact_block_velocities(ContactBlock& k, const float* const vel[6]) {
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
  static const bool gathers = __builtin_cpu_supports("avx2") != 0;
  if (gathers) {
    velocities_gathered(k, vel);
    return;
  }
#endif
  for (int s = 0; s < 2; ++s) {
    for (int l = 0; l < kContactLanes; ++l) {
      const std::int32_t b = k.bodies[s][l];
      for (int f = 0; f < 6; ++f) k.vel[s][f][l] = vel[f][b];
    }
  }
}

void contact_block_solve(ContactBlock& k, uint flags) {
  // contact_solve reads only these three flags.
  switch (flags &
          (MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_IMPULSE_RELAX | MOTES_FLAG_IMPULSE_SPLIT)) {
    case 0u:
      solve_lanes<0u>(k);
      break;
    case MOTES_FLAG_IMPULSE_SPLIT:
      solve_lanes<MOTES_FLAG_IMPULSE_SPLIT>(k);
      break;
    case MOTES_FLAG_IMPULSE_RELAX:
      solve_lanes<MOTES_FLAG_IMPULSE_RELAX>(k);
      break;
    case MOTES_FLAG_IMPULSE_COUNT:
      solve_lanes<MOTES_FLAG_IMPULSE_COUNT>(k);
      break;
    default:
      solve_lanes<MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_IMPULSE_RELAX>(k);
      break;
  }
}

}  // namespace motes::openmp
