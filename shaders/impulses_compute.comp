#version 450
// impulses_compute: every dynamic rigid particle (one thread per particle id) sums the impulses of
// its contacts with the rigid particles of its list, in list order (a particle with more
// neighbours than its list holds walks the grid of the last build instead: the same pairs in the
// same order), then the planes, and writes only its own impulse, count and moment
// (shared/impulse.h). Each pair is evaluated lower id first, so the two particles of a contact get
// bitwise opposite impulses; each keeps the contact's accumulated impulse in its own slot of
// ContactImpulse (valid while ImpulseStamp matches the lists' build; a correcting sweep of split
// impulses, MOTES_FLAG_IMPULSE_SPLIT, in ContactImpulseSplit, which the last relaxing sweep,
// MOTES_FLAG_IMPULSE_PUSH, fills too). As backends/openmp/impulses_compute.cpp.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY
#include "kernel_common.glsl"
#include "shared/grid_hash.h"
#include "shared/neighbours.h"
#include "grid_walk.glsl"

ImpulseBody impulse_body(uint b) {
  return impulse_body_of(body_pos[b], body_quat[b], body_inv_inertia[b], body_vel[b],
                         body_angvel[b], body_vel_start[b], body_angvel_start[b], p.flags);
}

/// The accumulated impulse of a slot as this pass keeps them (ContactImpulseSplit for a correcting
/// sweep of split impulses).
vec4 acc_read(uint slot) {
  return (p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u ? contact_impulse_split[slot]
                                                    : contact_impulse_acc[slot];
}

/// Writes it there (and, for the last relaxing sweep, to ContactImpulseSplit too).
void acc_write(uint slot, vec4 a) {
  if ((p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u) {
    contact_impulse_split[slot] = a;
    return;
  }
  contact_impulse_acc[slot] = a;
  if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) contact_impulse_split[slot] = a;
}

void main() {
  uint i = thread_index();
  if (i >= p.rigid_particle_count) return;
  if (particle_vel[i].w == 0.0f) {  // static particle: its impulse is never used
    particle_force[i] = vec4(0.0f);
    particle_moment[i] = vec4(0.0f);
    return;
  }
  float margin = impulse_margin(p.neighbour_skin);
  uint bi = particle_body[i];
  vec4 xi = contact_particle(particle_pos[i], body_quat[bi], particle_local[i], p.flags);
  ImpulseBody own = impulse_body(bi);
  uint law_base = particle_material[i] * p.material_count;
  uint builds = neighbour_state[MOTES_NEIGHBOUR_BUILDS];
  bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  uint own_stamp = impulse_stamp[i];
  uint nr = p.rigid_particle_count;
  vec4 sum = vec4(0.0f);
  vec3 moment_sum = vec3(0.0f);
  uint c = neighbour_count[i];
  if (c <= p.neighbour_capacity) {
    for (uint k = 0u; k < c; ++k) {
      uint j = list_entry(k, i);
      if (j >= p.rigid_particle_count) continue;
      bool slotted = impulse_pair_slotted(c, neighbour_count[j], p.neighbour_capacity);
      uint slot = k * nr + i;
      bool valid = !counting ||
                   impulse_slots_valid(own_stamp, impulse_stamp[j], particle_vel[j].w, builds);
      vec4 a = slotted && valid ? acc_read(slot) : vec4(0.0f);
      uint bj = particle_body[j];
      vec4 xj = contact_particle(particle_pos[j], body_quat[bj], particle_local[j], p.flags);
      vec3 arm;
      vec4 r = pair_impulse(own, xi, impulse_body(bj), xj, i < j, margin,
                            contact_laws[pair_law_index(i, particle_material[i], j,
                                                         particle_material[j],
                                                         p.material_count)],
                            p.gravity_dt, p.flags, a, arm);
      if (slotted) acc_write(slot, a);
      impulse_add(sum, moment_sum, r, arm, p.flags);
    }
  } else {
    GridWalk walk = grid_walk_begin(neighbour_ref_pos[i]);
    uint lo, hi;
    while (grid_walk_next(walk, lo, hi)) {
      for (uint t = lo; t < hi; ++t) {
        if (contact_excluded(sorted_body[t], bi)) continue;
        uint j = grid_order[t];
        if (j >= p.rigid_particle_count) continue;
        uint bj = particle_body[j];
        vec4 xj = contact_particle(particle_pos[j], body_quat[bj], particle_local[j], p.flags);
        vec4 none = vec4(0.0f);  // no slot beyond the list's capacity
        vec3 arm;
        vec4 q = pair_impulse(own, xi, impulse_body(bj), xj, i < j, margin,
                              contact_laws[pair_law_index(i, particle_material[i], j,
                                                          particle_material[j],
                                                          p.material_count)],
                              p.gravity_dt, p.flags, none, arm);
        impulse_add(sum, moment_sum, q, arm, p.flags);
      }
    }
  }
  for (uint k = 0u; k < p.plane_count; ++k) {
    PlaneData pl = planes[k];
    uint slot = (p.neighbour_capacity + k) * nr + i;
    vec4 a = acc_read(slot);
    vec3 arm;
    vec4 r = plane_contact_impulse(own, xi, pl.normal_offset, margin,
                                   contact_laws[law_base + pl.material], p.gravity_dt, p.flags, a,
                                   arm);
    acc_write(slot, a);
    impulse_add(sum, moment_sum, r, arm, p.flags);
  }
  particle_force[i] = sum;
  particle_moment[i] = vec4(moment_sum, 0.0f);
}
