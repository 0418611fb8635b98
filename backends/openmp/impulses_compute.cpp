// impulses_compute: every dynamic rigid particle sums the impulses of its contacts with the rigid
// particles of its list, in list order (a particle with more neighbours than its list holds walks
// the grid of the last build instead: the same pairs in the same order), then the planes, and
// writes only its own impulse, count and moment (shared/impulse.h). Each pair is evaluated with
// the lower particle id first, so the two particles of a contact get bitwise opposite impulses;
// each keeps the contact's accumulated impulse in its own slot of ContactImpulse (the same bits
// on both sides). The counting pass reads the slots only while the lists are those that wrote them
// (ImpulseStamp), and stamps them. The sweeps visit only the particles that the counting pass
// found with a contact within reach (the others' results are zeros that stay so).
#include <algorithm>
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/grid_walk.h"
#include "shared/impulse.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::impulses_compute(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(p.rigid_particle_count);
  const std::size_t stride = p.particle_count;
  const uint capacity = p.neighbour_capacity;
  const uint materials = p.material_count;
  const float margin = shared::impulse_margin(p.neighbour_skin);
  const ContactInputs in = contact_inputs();
  const vec4* com = buf<vec4>(Buffer::BodyPos);
  const vec4* quat = buf<vec4>(Buffer::BodyQuat);
  const vec4* inv_inertia = buf<vec4>(Buffer::BodyInvInertia);
  const vec4* body_vel = buf<vec4>(Buffer::BodyVel);
  const vec4* body_angvel = buf<vec4>(Buffer::BodyAngVel);
  const vec4* vel0 = buf<vec4>(Buffer::BodyVelStart);
  const vec4* angvel0 = buf<vec4>(Buffer::BodyAngVelStart);
  vec4* impulse = buf<vec4>(Buffer::ParticleForce);
  vec4* moment = buf<vec4>(Buffer::ParticleMoment);
  // The accumulated impulses this pass reads and writes (a correcting sweep of split impulses:
  // ContactImpulseSplit), and where it copies them (the last relaxing sweep).
  vec4* acc = buf<vec4>((p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u ? Buffer::ContactImpulseSplit
                                                                   : Buffer::ContactImpulse);
  vec4* copy =
      (p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u ? buf<vec4>(Buffer::ContactImpulseSplit) : nullptr;
  const auto keep = [acc, copy](std::size_t at, const vec4& a) {
    acc[at] = a;
    if (copy != nullptr) copy[at] = a;
  };
  uint* stamp = buf<uint>(Buffer::ImpulseStamp);
  const uint builds = buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_BUILDS];
  const bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  const std::size_t nr = p.rigid_particle_count;
  // Each body's frame (centre, world inverse inertia) once per substep: poses do not move
  // between a counting pass and its sweeps (of impulse contacts).
  const auto bodies = static_cast<std::int64_t>(p.body_count);
  // The velocity pass of position contacts follows a projection that moved the poses.
  const bool moved = (p.flags & MOTES_FLAG_POSITION_VELOCITY) != 0u;
  if (counting || moved || impulse_frames_.size() != std::size_t(bodies)) {
    impulse_frames_.resize(std::size_t(bodies));
    shared::ImpulseBody* frames = impulse_frames_.data();
    for_items(bodies, parallel(bodies), [&](std::int64_t b) {
      frames[b] = shared::impulse_body_frame(com[b], quat[b], inv_inertia[b]);
    });
  }
  const shared::ImpulseBody* frames = impulse_frames_.data();
  // Each rigid particle as its contacts take it (shared::contact_particle): particles_update
  // makes them with the positions; here when it has not since the poses last changed.
  const bool positions = (p.flags & MOTES_FLAG_POSITION) != 0u;
  if (!positions && (!impulse_points_ready_ || impulse_points_.size() != std::size_t(n))) {
    impulse_points_.resize(std::size_t(n));
    vec4* points = impulse_points_.data();
    const vec4* local = buf<vec4>(Buffer::ParticleLocal);
    for_items(n, parallel(n), [&](std::int64_t i) {
      points[i] = shared::contact_particle(in.pos[i], quat[in.body[i]], local[i], p.flags);
    });
    impulse_points_ready_ = true;
  }
  const vec4* xs = positions ? in.pos : impulse_points_.data();
  const auto impulse_body = [&](uint b) {
    shared::ImpulseBody s = frames[b];
    shared::impulse_body_state(s, body_vel[b], body_angvel[b], vel0[b], angvel0[b], p.flags);
    return s;
  };

  // The sweeps: each contact of two dynamic rigid particles with slots in both lists is evaluated
  // once, by the lower id (pair_impulse's own order, so the same bits as the higher id's own
  // evaluation), its impulse kept for both slots and its accumulated impulse written to both.
  // impulse_mirror_ holds each slot's place in the partner's list, made when the lists change.
  constexpr uint kNoMirror = 0xffffffffu;
  const std::size_t slots = std::size_t{capacity} * nr;
  if (counting && impulse_mirror_.size() != slots) {
    impulse_mirror_.assign(slots, kNoMirror);
    impulse_pair_.resize(slots);
    uint* mirror = impulse_mirror_.data();
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(n))
    for (std::int64_t i = 0; i < n; ++i) {
      const uint c = in.count[i];
      if (in.vel[i].w == 0.0f || c > capacity) continue;
      for (uint k = 0; k < c; ++k) {
        const uint j = in.list[std::size_t{k} * stride + std::size_t(i)];
        if (j >= p.rigid_particle_count || in.vel[j].w == 0.0f || in.count[j] > capacity) continue;
        for (uint m = 0; m < in.count[j]; ++m) {
          if (in.list[std::size_t{m} * stride + j] == uint(i)) {
            mirror[std::size_t{k} * nr + std::size_t(i)] = m;
            break;
          }
        }
      }
    }
  }
  // Set for the sweeps over the active particles, after lower_pairs has run.
  bool pairs_once = false;
  const uint* mirror = impulse_mirror_.data();
  vec4* pair_r = impulse_pair_.data();
  // The contacts of an active particle i in its mirrored slots with the higher ids, and with the
  // lower ids that are not active (none evaluates those for them: out of reach, the same result).
  const auto lower_pairs = [&](std::int64_t i, const std::uint8_t* active) {
    const uint c = in.count[i];
    if (in.vel[i].w == 0.0f || c > capacity) return;
    const vec4 xi = xs[i];
    bool built = false;
    shared::ImpulseBody own;
    for (uint k = 0; k < c; ++k) {
      const std::size_t at = std::size_t{k} * nr + std::size_t(i);
      const uint m = mirror[at];
      const uint j = in.list[std::size_t{k} * stride + std::size_t(i)];
      if (m == kNoMirror || (j < uint(i) && active[j] != 0)) continue;
      if (!built) {
        own = impulse_body(in.body[i]);
        built = true;
      }
      const std::size_t other_at = std::size_t{m} * nr + j;
      vec4 a = acc[at];
      vec4 on_j;  // j's side, as pair_impulse gives it
      pair_r[at] = shared::pair_impulse_sides(
          own, xi, impulse_body(in.body[j]), xs[j], uint(i) < j, margin,
          in.laws[shared::pair_law_index(uint(i), in.material[i], j, in.material[j], materials)],
          p.gravity_dt, p.flags, a, on_j);
      pair_r[other_at] = on_j;
      keep(at, a);
      keep(other_at, a);
    }
  };

  // One particle's contacts: its list (or the grid beyond K), then the planes. defer: a counting
  // pass that keeps its contacts (impulses_count_kept) only finds which particles touch.
  bool defer = false;
  const auto particle = [&](std::int64_t i) {
    const vec4 xi = xs[i];
    if (in.vel[i].w == 0.0f) {  // static particle: its impulse is never used
      impulse[i] = vec4(0.0f);
      moment[i] = vec4(0.0f);
      return false;
    }
    const uint c = in.count[i];
    if (counting && c <= capacity) {
      // Nothing within reach (the common case: most particles touch nothing): the result of the
      // full evaluation below, without building the bodies: every slot of a contact out of reach
      // is cleared, no impulse, no count.
      // The tests of pair_impulse and plane_contact_impulse, from the same numbers.
      const shared::ImpulseBody& own_frame = frames[in.body[i]];
      bool touches = false;
      for (uint k = 0; k < c && !touches; ++k) {
        const uint j = in.list[std::size_t{k} * stride + std::size_t(i)];
        if (j >= p.rigid_particle_count) continue;
        vec4 xa, xb;
        shared::pair_places(own_frame.com, xi, frames[in.body[j]].com, xs[j], uint(i) < j, p.flags,
                            xa, xb);
        touches = shared::pair_within_reach(xa, xb, margin);
      }
      for (uint k = 0; k < p.plane_count && !touches; ++k) {
        const vec4 no = shared::contact_plane(in.planes[k].normal_offset, own_frame, p.flags);
        touches = shared::dot(shared::xyz(no), shared::xyz(xi)) - no.w - xi.w < margin;
      }
      if (!touches) {
        for (uint k = 0; k < c; ++k) {
          const uint j = in.list[std::size_t{k} * stride + std::size_t(i)];
          if (j < p.rigid_particle_count &&
              shared::impulse_pair_slotted(c, in.count[j], capacity)) {
            acc[std::size_t{k} * nr + std::size_t(i)] = vec4(0.0f);
          }
        }
        for (uint k = 0; k < p.plane_count; ++k) {
          acc[(std::size_t{capacity} + k) * nr + std::size_t(i)] = vec4(0.0f);
        }
        impulse[i] = vec4(0.0f);
        moment[i] = vec4(0.0f);
        return false;
      }
      if (defer) return true;
    }
    const uint bi = in.body[i];
    const shared::ImpulseBody own = impulse_body(bi);
    const shared::ContactLaw* law_row = in.laws + std::size_t{in.material[i]} * materials;
    const uint own_stamp = stamp[i];
    vec4 sum(0.0f);
    vec3 moment_sum(0.0f);
    // The impulse of the contact with particle j (rigid particles only), added in order; its
    // accumulated impulse in slot `slot` (nullptr: none).
    auto add_contact = [&](uint j, vec4* slot) {
      if (j >= p.rigid_particle_count) return;
      const vec4 xj = xs[j];
      const shared::ImpulseBody other = impulse_body(in.body[j]);
      const bool valid =
          !counting || shared::impulse_slots_valid(own_stamp, stamp[j], in.vel[j].w, builds);
      vec4 a = slot != nullptr && valid ? *slot : vec4(0.0f);
      vec3 arm;
      const vec4 r = shared::pair_impulse(
          own, xi, other, xj, static_cast<uint>(i) < j, margin,
          in.laws[shared::pair_law_index(uint(i), in.material[i], j, in.material[j], materials)],
          p.gravity_dt, p.flags, a, arm);
      if (slot != nullptr) keep(std::size_t(slot - acc), a);
      shared::impulse_add(sum, moment_sum, r, arm, p.flags);
    };
    if (c <= capacity) {
      for (uint k = 0; k < c; ++k) {
        const uint j = in.list[std::size_t{k} * stride + std::size_t(i)];
        if (pairs_once && mirror[std::size_t{k} * nr + std::size_t(i)] != kNoMirror) {
          const bool own_first = uint(i) < j;
          const shared::ContactPair pr =
              shared::contact_pair(own, xi, frames[in.body[j]], xs[j], own_first, p.flags);
          shared::impulse_add(sum, moment_sum, pair_r[std::size_t{k} * nr + std::size_t(i)],
                              shared::pair_contact_arm(pr, !own_first, p.flags), p.flags);
          continue;
        }
        const bool slotted =
            j < p.rigid_particle_count && shared::impulse_pair_slotted(c, in.count[j], capacity);
        add_contact(j, slotted ? acc + std::size_t{k} * nr + std::size_t(i) : nullptr);
      }
    } else {
      shared::grid_walk(p, in.ref[i], in.cell_start, [&](uint lo, uint hi) {
        for (uint t = lo; t < hi; ++t) {
          if (!shared::contact_excluded(in.sbody[t], bi)) add_contact(in.order[t], nullptr);
        }
      });
    }
    for (uint k = 0; k < p.plane_count; ++k) {
      const shared::PlaneData pl = in.planes[k];
      const std::size_t at = (std::size_t{capacity} + k) * nr + std::size_t(i);
      vec4 a = acc[at];
      vec3 arm;
      const vec4 r = shared::plane_contact_impulse(
          own, xi, pl.normal_offset, margin, law_row[pl.material], p.gravity_dt, p.flags, a, arm);
      keep(at, a);
      shared::impulse_add(sum, moment_sum, r, arm, p.flags);
    }
    impulse[i] = sum;
    moment[i] = vec4(moment_sum, 0.0f);
    return true;
  };

  // Only the sweeps from kept frames keep accumulated impulses in their lanes.
  if (counting || impulse_touches_.size() != std::size_t(n)) impulse_acc_flush();
  if (counting) {
    // From kept contact frames where it can (impulses_sweep.cpp: which particles touch
    // something, their contacts, the warm start), else here.
    if (impulses_count_kept(p)) {
      record(Kernel::ImpulsesCompute, start);
      return;
    }
    // Without kept contact frames: which particles touch something (2: within their lists'
    // capacity, evaluated below; 1: the others, evaluated here, walking the grid).
    impulse_touches_.resize(std::size_t(n));
    std::uint8_t* touches = impulse_touches_.data();
    defer = true;
    for_items(n, parallel_heavy(n), [&](std::int64_t i) {
      touches[i] = particle(i) ? (in.count[i] <= capacity ? 2 : 1) : 0;
    });
    defer = false;
    impulse_active_.clear();
    for (std::int64_t i = 0; i < n; ++i) {
      if (touches[i] != 0) impulse_active_.push_back(static_cast<uint>(i));
    }
    // Each body's touching particles: a run of the ascending active list (impulses_apply).
    impulse_runs_update(p);
    const auto active = static_cast<std::int64_t>(impulse_active_.size());
    const uint* ids = impulse_active_.data();
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(active))
    for (std::int64_t a = 0; a < active; ++a) {
      if (touches[ids[a]] == 2) particle(ids[a]);
    }
  } else if (impulse_touches_.size() != std::size_t(n)) {
    // No counting pass at these sizes yet: every particle.
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n))
    for (std::int64_t i = 0; i < n; ++i) particle(i);
  } else if (impulses_sweep(p)) {
    // The sweeps of this substep from its contacts' kept frames (impulses_sweep.cpp).
  } else {
    // The sweeps of this substep: only the particles the counting pass found touching (a
    // contact within reach touches both), their shared contacts first.
    impulse_acc_flush();
    const auto active = static_cast<std::int64_t>(impulse_active_.size());
    const uint* ids = impulse_active_.data();
    // Position contacts may move one side of a contact alone: no mirrored results.
    pairs_once = impulse_mirror_.size() == slots && (p.flags & MOTES_FLAG_POSITION) == 0u;
#pragma omp parallel num_threads(team_) if (parallel_heavy(active))
    {
      if (pairs_once) {
#pragma omp for schedule(static)
        for (std::int64_t a = 0; a < active; ++a) lower_pairs(ids[a], impulse_touches_.data());
      }
#pragma omp for schedule(static)
      for (std::int64_t a = 0; a < active; ++a) particle(ids[a]);
    }
  }
  record(Kernel::ImpulsesCompute, start);
}

}  // namespace motes::openmp
