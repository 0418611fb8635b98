// impulses_compute's counting pass and sweeps from kept contact frames (openmp only; the same
// bits as evaluating every contact from scratch, as the GPU kernels do). Poses and the velocities
// at a substep's start do not change between its counting pass and its pose, so the counting pass
// lists the contacts within reach once, each with its shared::ContactFrame (arms, normal,
// separation, start velocity), the first sweep adds each one's response to a unit normal impulse
// (it needs the contact counts the counting pass makes), and every pass of the substep solves that
// list (shared::contact_solve) and sums each active particle's contacts in the order
// impulses_compute sums them: its list, then the planes. A contact of two dynamic particles is one
// entry for both (the lower id's side; the higher id takes it negated, about its own arm).
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
  const std::size_t nr = p.rigid_particle_count;
  const std::size_t stride = p.particle_count;
  const uint capacity = p.neighbour_capacity;
  const uint materials = p.material_count;
  const float margin = shared::impulse_margin(p.neighbour_skin);
  const ContactInputs in = contact_inputs();
  const uint* stamp = buf<uint>(Buffer::ImpulseStamp);
  const uint builds = buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_BUILDS];
  vec4* acc = buf<vec4>(Buffer::ContactImpulse);
  const uint wall = p.body_count;
  const shared::ImpulseBody* bodies = impulse_bodies_.data();
  const std::vector<uint>& active = impulse_active_;
  const std::uint8_t* touches = impulse_touches_.data();
  // Every contact of a particle beyond its list's capacity walks the grid: not kept.
  for (const uint i : active) {
    if (in.count[i] > capacity) return false;
  }
  const bool mirrored = impulse_mirror_.size() == std::size_t{capacity} * nr;
  impulse_contacts_.clear();
  impulse_entries_.clear();
  impulse_entry_first_.assign(active.size() + 1, 0u);
  impulse_slot_contact_.resize(std::size_t{capacity} * nr);
  uint* slot_contact = impulse_slot_contact_.data();
  for (std::size_t a = 0; a < active.size(); ++a) {
    const uint i = active[a];
    const vec4 xi = in.pos[i];
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
      // particle_contact_impulse's test and frame, the lower id as a.
      const bool own_first = i < j;
      const vec4 xa = own_first ? xi : in.pos[j];
      const vec4 xb = own_first ? in.pos[j] : xi;
      const vec3 d = shared::xyz(xa) - shared::xyz(xb);
      const float dist2 = shared::dot(d, d);
      const float rsum = xa.w + xb.w;
      const float reach = rsum + margin;
      const bool near = !(dist2 >= reach * reach || dist2 == 0.0f);
      const bool slotted = shared::impulse_pair_slotted(c, in.count[j], capacity);
      if (m != kNone) {
        slot_contact[std::size_t{m} * nr + j] = near ? uint(impulse_contacts_.size()) : kNone;
      }
      if (!near) {
        if (counting && slotted) acc[at] = vec4(0.0f);  // particle_contact_impulse's clearing
        continue;
      }
      const float dist = shared::sqrt(dist2);
      ImpulseContact ct;
      ct.a = own_first ? in.body[i] : in.body[j];
      ct.b = own_first ? in.body[j] : in.body[i];
      ct.law = in.laws[shared::pair_law_index(i, in.material[i], j, in.material[j], materials)];
      ct.frame =
          shared::contact_frame(bodies[ct.a], bodies[ct.b], shared::pair_contact_point(xa, xb),
                                d / dist, dist - rsum, rsum, ct.law.restitution, p.gravity_dt);
      if (!counting) shared::contact_frame_response(ct.frame, bodies[ct.a], bodies[ct.b]);
      ct.slot = slotted ? uint(at) : kNone;
      ct.mirror = m != kNone ? uint(std::size_t{m} * nr + j) : kNone;
      // The counting pass's warm start (impulse_slots_valid, alike for both particles of a pair).
      ct.warm = !counting || shared::impulse_slots_valid(stamp[i], stamp[j], in.vel[j].w, builds);
      impulse_entries_.push_back(uint(impulse_contacts_.size()) * 2u + (own_first ? 0u : 1u));
      impulse_contacts_.push_back(ct);
    }
    const uint own_law = in.material[i] * materials;
    for (uint k = 0; k < p.plane_count; ++k) {
      const vec4 no = in.planes[k].normal_offset;
      const float sep = shared::dot(shared::xyz(no), shared::xyz(xi)) - no.w - xi.w;
      const std::size_t slot = (std::size_t{capacity} + k) * nr + i;
      if (sep >= margin) {  // plane_contact_impulse's test and clearing
        if (counting) acc[slot] = vec4(0.0f);
        continue;
      }
      ImpulseContact ct;
      ct.a = in.body[i];
      ct.b = wall;
      ct.law = in.laws[own_law + in.planes[k].material];
      ct.frame =
          shared::contact_frame(bodies[ct.a], bodies[wall], shared::plane_contact_point(xi, no),
                                shared::xyz(no), sep, xi.w, ct.law.restitution, p.gravity_dt);
      if (!counting) shared::contact_frame_response(ct.frame, bodies[ct.a], bodies[wall]);
      ct.slot = uint(slot);
      ct.mirror = kNone;
      ct.warm = true;
      impulse_entries_.push_back(uint(impulse_contacts_.size()) * 2u);
      impulse_contacts_.push_back(ct);
    }
    impulse_entry_first_[a + 1] = uint(impulse_entries_.size());
  }
  impulse_results_.resize(impulse_contacts_.size());
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
  for_items(bodies, parallel(bodies), [&](std::int64_t b) {
    shared::ImpulseBody s = frames[b];
    shared::impulse_body_state(s, body_vel[b], body_angvel[b], vel0[b], angvel0[b], p.flags);
    state[b] = s;
  });
  state[bodies] = shared::impulse_wall();
}

void OpenMPDevice::impulse_contacts_solve(const shared::StepParams& p) {
  const bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  const auto contacts = static_cast<std::int64_t>(impulse_contacts_.size());
  const auto active = static_cast<std::int64_t>(impulse_active_.size());
  ImpulseContact* list = impulse_contacts_.data();
  const shared::ImpulseBody* state = impulse_bodies_.data();
  vec4* result = impulse_results_.data();
  vec4* acc = buf<vec4>(Buffer::ContactImpulse);
  vec4* impulse = buf<vec4>(Buffer::ParticleForce);
  vec4* moment = buf<vec4>(Buffer::ParticleMoment);
  const uint* ids = impulse_active_.data();
  const uint* first = impulse_entry_first_.data();
  const uint* entries = impulse_entries_.data();
  const bool respond = !counting && !impulse_responses_ready_;
  impulse_responses_ready_ = !counting;
  const auto solve = [&](std::int64_t c) {
    ImpulseContact& ct = list[c];
    // The first sweep after the counting pass: the bodies' contact counts are known now.
    if (respond) shared::contact_frame_response(ct.frame, state[ct.a], state[ct.b]);
    vec4 a = ct.slot != kNone && (ct.warm || !counting) ? acc[ct.slot] : vec4(0.0f);
    result[c] = shared::contact_solve(state[ct.a], state[ct.b], ct.frame, ct.law, p.flags, a);
    if (ct.slot != kNone) acc[ct.slot] = a;
    if (ct.mirror != kNone) acc[ct.mirror] = a;
  };
  const auto add = [&](std::int64_t a) {
    vec4 sum(0.0f);
    vec3 moment_sum(0.0f);
    for (uint e = first[a]; e < first[a + 1]; ++e) {
      const uint c = entries[e] >> 1u;
      const vec4 r = result[c];
      if ((entries[e] & 1u) == 0u) {
        sum = sum + r;
        moment_sum += shared::cross(shared::xyz(list[c].frame.ra), shared::xyz(r));
      } else {  // the higher id's side: pair_impulse's negation, about its own arm
        const vec4 q(-r.x, -r.y, -r.z, r.w);
        sum = sum + q;
        moment_sum += shared::cross(shared::xyz(list[c].frame.rb), shared::xyz(q));
      }
    }
    impulse[ids[a]] = sum;
    moment[ids[a]] = vec4(moment_sum, 0.0f);
  };
  if (!parallel_heavy(active)) {
    for (std::int64_t c = 0; c < contacts; ++c) solve(c);
    for (std::int64_t a = 0; a < active; ++a) add(a);
    return;
  }
#pragma omp parallel num_threads(team_)
  {
#pragma omp for schedule(static)
    for (std::int64_t c = 0; c < contacts; ++c) solve(c);
#pragma omp for schedule(static)
    for (std::int64_t a = 0; a < active; ++a) add(a);
  }
}

bool OpenMPDevice::impulses_count_kept(const shared::StepParams& p) {
  impulse_contacts_ready_ = false;
  // Position contacts keep no frames: their passes change what a frame would hold.
  if ((p.flags & MOTES_FLAG_POSITION) != 0u) return false;
  impulse_bodies_update(p);
  if (!impulse_contacts_build(p, true)) return false;
  impulse_contacts_ready_ = true;
  impulse_responses_ready_ = false;
  impulse_contacts_solve(p);
  return true;
}

bool OpenMPDevice::impulses_sweep(const shared::StepParams& p) {
  if ((p.flags & MOTES_FLAG_POSITION) != 0u) return false;
  impulse_bodies_update(p);
  if (!impulse_contacts_ready_) {
    if (!impulse_contacts_build(p, false)) return false;
    impulse_contacts_ready_ = true;
    impulse_responses_ready_ = true;
  }
  impulse_contacts_solve(p);
  return true;
}

}  // namespace motes::openmp
