// impulses_apply: each dynamic body sums its particles' impulses, counts and moments in particle
// order and applies them (shared/impulse.h: body_apply_impulse); with MOTES_FLAG_IMPULSE_COUNT it
// first keeps its velocities and contact count as the start of the impulse stage; with
// MOTES_FLAG_IMPULSE_PUSH it keeps the velocities it leaves in BodyVelPush and BodyAngMomPush.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/impulse.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::impulses_apply(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto bodies = static_cast<std::int64_t>(p.body_count);
  const bool count_only = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  const uint* first = buf<uint>(Buffer::BodyFirst);
  vec4* com = buf<vec4>(Buffer::BodyPos);  // moved by the projection of position contacts
  vec4* quat = buf<vec4>(Buffer::BodyQuat);
  const vec4* inv_inertia = buf<vec4>(Buffer::BodyInvInertia);
  const vec4* impulse = buf<vec4>(Buffer::ParticleForce);
  const vec4* moment = buf<vec4>(Buffer::ParticleMoment);
  vec4* vel = buf<vec4>(Buffer::BodyVel);
  vec4* angmom = buf<vec4>(Buffer::BodyAngMom);
  vec4* angvel = buf<vec4>(Buffer::BodyAngVel);
  vec4* vel0 = buf<vec4>(Buffer::BodyVelStart);
  vec4* angvel0 = buf<vec4>(Buffer::BodyAngVelStart);
  const bool push = (p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u;
  // The counting pass has read every slot: the bodies' particles' slots are now this build's.
  uint* stamp = count_only ? buf<uint>(Buffer::ImpulseStamp) : nullptr;
  const uint builds = count_only ? buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_BUILDS] : 0u;
  vec4* vel_push = push ? buf<vec4>(Buffer::BodyVelPush) : nullptr;
  vec4* angmom_push = push ? buf<vec4>(Buffer::BodyAngMomPush) : nullptr;

  // In the impulse stage (after a counting pass of impulses_compute at these sizes), the
  // particles it found touching something; not when applying what attachments did
  // (MOTES_FLAG_ABSORB: every particle may have some).
  const std::uint8_t* touches =
      (p.flags & MOTES_FLAG_ABSORB) == 0u &&
              impulse_touches_.size() == std::size_t{p.rigid_particle_count} &&
              p.rigid_particle_count > 0
          ? impulse_touches_.data()
          : nullptr;
  // Each body's run of them in the ascending list of touching particles (impulses_compute).
  const uint* runs = touches != nullptr && impulse_body_active_.size() == std::size_t(bodies) + 1
                         ? impulse_body_active_.data()
                         : nullptr;
  const uint* active = impulse_active_.data();
  // The counting pass before the last projection sweep of position contacts: each body's contact
  // Gram bound too (shared/contact_gram.h), from its particles' centres.
  const bool gram = (p.flags & MOTES_FLAG_POSITION_GRAM) != 0u;
  const vec4* pos = gram ? buf<vec4>(Buffer::ParticlePos) : nullptr;
  for_items(bodies, parallel(bodies), [&](std::int64_t b) {
    // The sums in the contract's order (shared/impulse.h, MOTES_BODY_CHUNK): each chunk of the
    // body's particles in particle order, then the chunks in order. A chunk without touching
    // particles adds zeros, which change nothing: skipped, as those particles are.
    vec4 sum(0.0f);
    vec3 m(0.0f);
    vec4 part(0.0f);
    vec3 part_m(0.0f);
    uint chunk = 0;
    shared::ContactGram g;
    shared::ContactGram part_g;
    if (gram) {
      g = shared::gram_zero();
      part_g = shared::gram_zero();
    }
    const auto close_chunk = [&] {
      sum = sum + part;
      m += part_m;
      part = vec4(0.0f);
      part_m = vec3(0.0f);
      if (gram) {
        shared::gram_merge(g, part_g);
        part_g = shared::gram_zero();
      }
    };
    const auto add = [&](uint i) {
      const uint c = shared::body_chunk(i, first[b]);
      if (c != chunk) {
        close_chunk();
        chunk = c;
      }
      part = part + impulse[i];
      part_m += shared::xyz(moment[i]);
      if (gram) {
        shared::gram_add(part_g, impulse[i], moment[i], shared::xyz(pos[i]) - shared::xyz(com[b]));
      }
    };
    if (com[b].w != 0.0f && runs != nullptr) {
      for (uint k = runs[b]; k < runs[b + 1]; ++k) add(active[k]);  // the same particles in order
    } else if (com[b].w != 0.0f) {
      for (uint i = first[b]; i < first[b + 1]; ++i) {
        // A particle the counting pass found touching nothing has zeros, whose sum changes
        // nothing: skip reading them.
        if (touches != nullptr && touches[i] == 0) continue;
        add(i);
      }
    }
    close_chunk();
    if (count_only) {  // the stage's start, then the warm start
      vel0[b] = shared::impulse_start_velocity(vel[b], vel0[b], sum.w, p.flags);
      angvel0[b] = shared::impulse_start_angular_velocity(angvel[b], angvel0[b], p.flags);
      if (gram) angvel0[b].w = shared::gram_bound(g, com[b], quat[b], inv_inertia[b]);
      if (com[b].w != 0.0f) {
        for (uint i = first[b]; i < first[b + 1]; ++i) stamp[i] = builds;
      }
    }
    shared::body_apply_contacts(com[b], quat[b], inv_inertia[b], vel[b], angmom[b], angvel[b],
                                shared::xyz(sum), m, p.gravity_dt, p.flags);
    if (push) {
      vel_push[b] = vel[b];
      angmom_push[b] = angmom[b];
    }
  });
  record(Kernel::ImpulsesApply, start);
}

}  // namespace motes::openmp
