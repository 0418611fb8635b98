// impulses_compute's counting pass and sweeps from kept contact frames (openmp only; the same
// bits as evaluating every contact from scratch, as the GPU kernels do). Poses and the velocities
// at a substep's start do not change between its counting pass and its pose, so the counting pass
// lists the contacts within reach once and makes each one's shared::ContactFrame (arms, normal,
// separation, start velocity), the first sweep adds each one's response to a unit normal impulse
// (it needs the contact counts the counting pass makes), and every pass of the substep solves that
// list (shared::contact_solve) and sums each active particle's contacts in the order
// impulses_compute sums them: its list, then the planes. A contact of two dynamic particles is one
// entry for both (the lower id's side; the higher id takes it negated, about its own arm). The
// contacts' numbers live in blocks of lanes (contact_lanes.h), where frames, responses and
// solves run in vector registers; their accumulated impulses stay there from the counting pass
// to the substep's last sweep and go back to ContactImpulse before anything else reads it
// (impulse_acc_flush).
#include <algorithm>
#include <cstdint>

#include "openmp_device.h"
#include "shared/impulse.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {
constexpr uint kNone = 0xffffffffu;
}  // namespace

bool OpenMPDevice::impulse_contacts_build(const shared::StepParams& p, bool counting) {
  impulse_acc_flush();
  const std::size_t nr = p.rigid_particle_count;
  const std::size_t stride = p.particle_count;
  const uint capacity = p.neighbour_capacity;
  const uint materials = p.material_count;
  const float margin = shared::impulse_margin(p.neighbour_skin);
  const ContactInputs in = contact_inputs();
  const vec4* xs = impulse_points_.data();  // shared::contact_particle, made by impulses_compute
  const uint* stamp = buf<uint>(Buffer::ImpulseStamp);
  const uint builds = buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_BUILDS];
  // A correcting sweep of split impulses starts from ContactImpulseSplit (impulses_compute).
  vec4* acc = buf<vec4>(!counting && (p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u
                            ? Buffer::ContactImpulseSplit
                            : Buffer::ContactImpulse);
  const uint wall = p.body_count;
  const shared::ImpulseBody* bodies = impulse_bodies_.data();
  vec4* impulse = buf<vec4>(Buffer::ParticleForce);
  vec4* moment = buf<vec4>(Buffer::ParticleMoment);
  // The counting pass visits every particle and finds which touch something (impulses_compute's
  // touching test and its clearing of the others, in one pass with the build); the sweeps, the
  // particles it found.
  const std::size_t n = counting ? nr : impulse_active_.size();
  if (counting) impulse_touches_.resize(nr);
  std::uint8_t* touches = impulse_touches_.data();
  std::vector<uint>& active = impulse_active_;
  // Every contact of a particle beyond its list's capacity walks the grid: not kept.
  for (std::size_t a = 0; a < n; ++a) {
    const uint i = counting ? uint(a) : active[a];
    if (in.vel[i].w != 0.0f && in.count[i] > capacity) return false;
  }
  if (counting) active.clear();
  const bool mirrored = impulse_mirror_.size() == std::size_t{capacity} * nr;
  // Contact `index` takes its lane (the blocks only grow: a block past the last is not read).
  const auto lane = [&](uint index) -> ContactBlock& {
    if (index / kContactLanes >= impulse_blocks_.size()) impulse_blocks_.emplace_back();
    return impulse_blocks_[index / kContactLanes];
  };
  impulse_contacts_.clear();
  impulse_entries_.clear();
  impulse_entry_first_.assign(1, 0u);
  impulse_slot_contact_.resize(std::size_t{capacity} * nr);
  uint* slot_contact = impulse_slot_contact_.data();
  for (std::size_t a = 0; a < n; ++a) {
    const uint i = counting ? uint(a) : active[a];
    if (in.vel[i].w == 0.0f) {  // static: never active, its impulse never used
      impulse[i] = vec4(0.0f);
      moment[i] = vec4(0.0f);
      touches[i] = 0;
      continue;
    }
    const std::size_t before = impulse_entries_.size();
    const vec4 xi = xs[i];
    const uint c = in.count[i];
    for (uint k = 0; k < c; ++k) {
      const uint j = in.list[std::size_t{k} * stride + i];
      if (j >= p.rigid_particle_count) continue;
      const std::size_t at = std::size_t{k} * nr + i;
      const uint m = mirrored ? impulse_mirror_[at] : kNone;
      if (m != kNone && j < i) {
        // Listed by the lower id already (kNone: out of reach); out of reach if it is not active.
        if (touches[j] != 0 && slot_contact[at] != kNone) {
          impulse_entries_.push_back(slot_contact[at] * 2u + 1u);
        } else if (counting) {
          acc[at] = vec4(0.0f);  // particle_contact_impulse's clearing, on this side too
        }
        continue;
      }
      // pair_impulse's pair, test and frame, the lower id as a.
      const bool own_first = i < j;
      vec4 xa, xb;
      shared::pair_places(bodies[in.body[i]].com, xi, bodies[in.body[j]].com, xs[j], own_first,
                          p.flags, xa, xb);
      const bool near = shared::pair_within_reach(xa, xb, margin);
      const bool slotted = shared::impulse_pair_slotted(c, in.count[j], capacity);
      if (m != kNone) {
        slot_contact[std::size_t{m} * nr + j] = near ? uint(impulse_contacts_.size()) : kNone;
      }
      if (!near) {
        if (counting && slotted) acc[at] = vec4(0.0f);  // particle_contact_impulse's clearing
        continue;
      }
      const shared::ContactPair pr = shared::contact_pair(
          bodies[in.body[i]], xi, bodies[in.body[j]], xs[j], own_first, p.flags);
      const vec3 d = shared::xyz(pr.xa) - shared::xyz(pr.xb);
      const float rsum = pr.xa.w + pr.xb.w;
      const float dist = shared::sqrt(shared::dot(d, d));
      const uint index = uint(impulse_contacts_.size());
      ImpulseContact& ct = impulse_contacts_.emplace_back();
      ct.a = own_first ? in.body[i] : in.body[j];
      ct.b = own_first ? in.body[j] : in.body[i];
      ct.slot = slotted ? uint(at) : kNone;
      ct.mirror = m != kNone ? uint(std::size_t{m} * nr + j) : kNone;
      // The counting pass's warm start (impulse_slots_valid, alike for both particles of a pair);
      // the sweeps always start from the slot.
      const bool warm =
          !counting || shared::impulse_slots_valid(stamp[i], stamp[j], in.vel[j].w, builds);
      contact_lane_start(
          lane(index), int(index % kContactLanes), ct.a, ct.b,
          shared::pair_contact_point(pr.xa, pr.xb), d / dist, dist - rsum, rsum, pr.a, pr.b,
          in.laws[shared::pair_law_index(i, in.material[i], j, in.material[j], materials)],
          ct.slot != kNone && warm ? acc[ct.slot] : vec4(0.0f));
      impulse_entries_.push_back(index * 2u + (own_first ? 0u : 1u));
    }
    const uint own_law = in.material[i] * materials;
    for (uint k = 0; k < p.plane_count; ++k) {
      const vec4 no =
          shared::contact_plane(in.planes[k].normal_offset, bodies[in.body[i]], p.flags);
      const float sep = shared::dot(shared::xyz(no), shared::xyz(xi)) - no.w - xi.w;
      const std::size_t slot = (std::size_t{capacity} + k) * nr + i;
      if (sep >= margin) {  // plane_contact_impulse's test and clearing
        if (counting) acc[slot] = vec4(0.0f);
        continue;
      }
      const uint index = uint(impulse_contacts_.size());
      ImpulseContact& ct = impulse_contacts_.emplace_back();
      ct.a = in.body[i];
      ct.b = wall;
      ct.slot = uint(slot);
      ct.mirror = kNone;
      contact_lane_start(lane(index), int(index % kContactLanes), ct.a, ct.b,
                         shared::plane_contact_point(xi, no), shared::xyz(no), sep, xi.w,
                         shared::contact_body(bodies[ct.a], p.flags), bodies[wall],
                         in.laws[own_law + in.planes[k].material], acc[slot]);
      impulse_entries_.push_back(index * 2u);
    }
    // A particle that touches something has a contact entry; one that does not has had its
    // slots cleared above, and has no impulse.
    if (counting) {
      touches[i] = impulse_entries_.size() > before ? 2 : 0;
      if (touches[i] == 0) {
        impulse[i] = vec4(0.0f);
        moment[i] = vec4(0.0f);
        continue;
      }
      active.push_back(i);
    }
    impulse_entry_first_.push_back(uint(impulse_entries_.size()));
  }
  if (counting) impulse_runs_update(p);
  // The frames, a block at a time; the last block's lanes past the last contact take none.
  const auto contacts = uint(impulse_contacts_.size());
  for (uint c = contacts; c % kContactLanes != 0u; ++c) {
    contact_lane_clear(lane(c), int(c % kContactLanes));
  }
  const std::size_t blocks = (std::size_t{contacts} + kContactLanes - 1) / kContactLanes;
  for (std::size_t k = 0; k < blocks; ++k) contact_block_frame(impulse_blocks_[k], p.gravity_dt);
  impulse_responses_ready_ = false;
  return true;
}

void OpenMPDevice::impulse_bodies_update(const shared::StepParams& p) {
  const auto bodies = static_cast<std::int64_t>(p.body_count);
  const vec4* body_vel = buf<vec4>(Buffer::BodyVel);
  const vec4* body_angvel = buf<vec4>(Buffer::BodyAngVel);
  const vec4* vel0 = buf<vec4>(Buffer::BodyVelStart);
  const vec4* angvel0 = buf<vec4>(Buffer::BodyAngVelStart);
  impulse_bodies_.resize(std::size_t(bodies) + 1);
  shared::ImpulseBody* state = impulse_bodies_.data();
  const shared::ImpulseBody* frames = impulse_frames_.data();
  // Their velocities now as six arrays too, one a component (contact_block_velocities).
  for (auto& v : impulse_velocities_) v.resize(std::size_t(bodies) + 1);
  float* v[6] = {impulse_velocities_[0].data(), impulse_velocities_[1].data(),
                 impulse_velocities_[2].data(), impulse_velocities_[3].data(),
                 impulse_velocities_[4].data(), impulse_velocities_[5].data()};
  for_items(bodies, parallel(bodies), [&](std::int64_t b) {
    shared::ImpulseBody s = frames[b];
    shared::impulse_body_state(s, body_vel[b], body_angvel[b], vel0[b], angvel0[b], p.flags);
    state[b] = s;
    v[0][b] = s.vel.x;
    v[1][b] = s.vel.y;
    v[2][b] = s.vel.z;
    v[3][b] = s.angvel.x;
    v[4][b] = s.angvel.y;
    v[5][b] = s.angvel.z;
  });
  state[bodies] = shared::impulse_wall();
  for (float* c : v) c[bodies] = 0.0f;
}

void OpenMPDevice::impulse_contacts_solve(const shared::StepParams& p) {
  const bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  const auto contacts = static_cast<std::int64_t>(impulse_contacts_.size());
  const auto active = static_cast<std::int64_t>(impulse_active_.size());
  const auto blocks = (contacts + kContactLanes - 1) / kContactLanes;
  const ImpulseContact* list = impulse_contacts_.data();
  const shared::ImpulseBody* state = impulse_bodies_.data();
  vec4* impulse = buf<vec4>(Buffer::ParticleForce);
  vec4* moment = buf<vec4>(Buffer::ParticleMoment);
  const uint* ids = impulse_active_.data();
  const uint* first = impulse_entry_first_.data();
  const uint* entries = impulse_entries_.data();
  ContactBlock* block = impulse_blocks_.data();
  const float* const velocities[6] = {impulse_velocities_[0].data(), impulse_velocities_[1].data(),
                                      impulse_velocities_[2].data(), impulse_velocities_[3].data(),
                                      impulse_velocities_[4].data(), impulse_velocities_[5].data()};
  // The first sweep after the counting pass: the bodies' contact counts are known now.
  const bool respond = !counting && !impulse_responses_ready_;
  if (!counting) impulse_responses_ready_ = true;
  // A block's pass: a sweep's lanes take their bodies' velocities now.
  const auto pass = [&](std::int64_t k) {
    ContactBlock& blk = block[k];
    const std::int64_t c0 = k * kContactLanes;
    const int lanes = int(std::min<std::int64_t>(kContactLanes, contacts - c0));
    if (!counting) {
      if (respond) {
        for (int l = 0; l < lanes; ++l) {
          const ImpulseContact& ct = list[c0 + l];
          contact_lane_bodies(blk, l, state[ct.a], state[ct.b]);
        }
        contact_block_respond(blk);
      }
      contact_block_velocities(blk, velocities);
    }
    contact_block_solve(blk, p.flags);
  };
  impulse_acc_pending_ = true;
  impulse_acc_into_ = AccInto::Main;
  if ((p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u) {
    impulse_acc_into_ = AccInto::Split;
  } else if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) {
    impulse_acc_into_ = AccInto::Both;
  }
  // Each active particle sums its contacts' results in order.
  const auto add = [&](std::int64_t a) {
    vec4 sum(0.0f);
    vec3 moment_sum(0.0f);
    for (uint e = first[a]; e < first[a + 1]; ++e) {
      const uint c = entries[e] >> 1u;
      const ContactBlock& blk = block[c / kContactLanes];
      const int l = int(c % kContactLanes);
      const vec4 r = contact_lane_vec4(blk.result, l);
      const float stack = blk.frame[15][l];  // the stack scale: each side's share (pair_impulse)
      if ((entries[e] & 1u) == 0u) {
        const vec4 q = shared::contact_side_impulse(r, stack, false);
        sum = sum + q;
        moment_sum += shared::cross(contact_lane_vec3(blk.frame, l), shared::xyz(q));
      } else {  // the higher id's side: pair_impulse's negation, about its own arm
        const vec4 q = shared::contact_side_impulse(r, stack, true);
        sum = sum + q;
        moment_sum += shared::cross(contact_lane_vec3(blk.frame + 4, l), shared::xyz(q));
      }
    }
    impulse[ids[a]] = sum;
    moment[ids[a]] = vec4(moment_sum, 0.0f);
  };
  // A team pays for itself from about a thousand contacts (the impulse chain of 500 ran 10%
  // slower on two threads than on one, of 2,000 11% faster: docs/benchmarks.md, issue 25).
  if (!parallel(contacts * 2)) {
    for (std::int64_t k = 0; k < blocks; ++k) pass(k);
    for (std::int64_t a = 0; a < active; ++a) add(a);
    impulse_acc_keep_relaxed();
    return;
  }
#pragma omp parallel num_threads(team_)
  {
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < blocks; ++k) pass(k);
#pragma omp for schedule(static)
    for (std::int64_t a = 0; a < active; ++a) add(a);
  }
  impulse_acc_keep_relaxed();
}

void OpenMPDevice::impulse_acc_keep_relaxed() {
  // The last relaxing sweep of split impulses: its accumulated impulses are ContactImpulse's at
  // the substep's end, whatever the correcting sweeps after it do in the lanes.
  if (impulse_acc_into_ != AccInto::Both) return;
  impulse_acc_relaxed_.resize(impulse_contacts_.size());
  for (std::size_t c = 0; c < impulse_contacts_.size(); ++c) {
    impulse_acc_relaxed_[c] =
        contact_lane_vec4(impulse_blocks_[c / kContactLanes].acc, int(c % kContactLanes));
  }
  impulse_acc_relaxed_pending_ = true;
}

void OpenMPDevice::impulse_acc_flush() {
  if (!impulse_acc_pending_) return;
  impulse_acc_pending_ = false;
  vec4* main = buf<vec4>(Buffer::ContactImpulse);
  vec4* split = buf<vec4>(Buffer::ContactImpulseSplit);
  const bool relaxed = impulse_acc_relaxed_pending_ && impulse_acc_into_ == AccInto::Split;
  impulse_acc_relaxed_pending_ = false;
  const auto put = [](vec4* acc, const ImpulseContact& ct, const vec4& a) {
    if (ct.slot != kNone) acc[ct.slot] = a;
    if (ct.mirror != kNone) acc[ct.mirror] = a;
  };
  for (std::size_t c = 0; c < impulse_contacts_.size(); ++c) {
    const ImpulseContact& ct = impulse_contacts_[c];
    const vec4 a =
        contact_lane_vec4(impulse_blocks_[c / kContactLanes].acc, int(c % kContactLanes));
    if (impulse_acc_into_ != AccInto::Split) put(main, ct, a);
    if (impulse_acc_into_ != AccInto::Main) put(split, ct, a);
    if (relaxed) put(main, ct, impulse_acc_relaxed_[c]);
  }
}

void OpenMPDevice::impulse_runs_update(const shared::StepParams& p) {
  const uint* first = buf<uint>(Buffer::BodyFirst);
  impulse_body_active_.resize(std::size_t{p.body_count} + 1);
  for (std::size_t b = 0; b <= p.body_count; ++b) {
    impulse_body_active_[b] =
        uint(std::lower_bound(impulse_active_.begin(), impulse_active_.end(), first[b]) -
             impulse_active_.begin());
  }
}

bool OpenMPDevice::impulses_count_kept(const shared::StepParams& p) {
  impulse_contacts_ready_ = false;
  // Position contacts keep no frames: their passes change what a frame would hold.
  if ((p.flags & MOTES_FLAG_POSITION) != 0u) return false;
  impulse_bodies_update(p);
  if (!impulse_contacts_build(p, true)) return false;
  impulse_contacts_ready_ = true;
  impulse_contacts_solve(p);
  return true;
}

bool OpenMPDevice::impulses_sweep(const shared::StepParams& p) {
  if ((p.flags & MOTES_FLAG_POSITION) != 0u) return false;
  impulse_bodies_update(p);
  if (!impulse_contacts_ready_) {
    if (!impulse_contacts_build(p, false)) return false;
    impulse_contacts_ready_ = true;
  }
  impulse_contacts_solve(p);
  return true;
}

}  // namespace motes::openmp
