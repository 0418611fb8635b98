#version 450
// neighbours_build (after neighbours_build_begin.comp, neighbours_update.comp or
// neighbours_update_small.comp): every dynamic particle (one thread per particle, in grid order)
// lists the particles of other bodies closer than r_i + r_j + skin (shared/neighbours.h) in the
// canonical order of the 27-cell walk, keeps the first K (entry k at k * N + i) and writes its full
// count; as backends/openmp/neighbours_build.cpp. The figures of the build (particles over capacity,
// largest count) are reduced per workgroup, then added with integer atomics.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/grid_hash.h"
#include "shared/neighbours.h"
#include "grid_walk.glsl"
#include "link_exclusions.glsl"

shared uint group_over;
shared uint group_most;

void main() {
  // Gated (args.y != 0: after neighbours_update_small.comp, dispatched directly): built only when
  // word args.x of IndirectArgs says so, the same for every invocation.
  if (args.y != 0u && indirect_args[args.x] == 0u) return;
  uint k = thread_index();
  if (gl_LocalInvocationID.x == 0u) {
    group_over = 0u;
    group_most = 0u;
  }
  barrier();
  if (k < p.particle_count) {
    // Threads in grid order: a subgroup's particles share their cells, whose candidates it then
    // reads together (each list is the same whichever thread builds it). Particle order, which
    // CUDA's build takes without fluid, made this one slower on an H200 (W1 dense 1 M: 0.017 ->
    // 0.021 ms a step; docs/benchmarks.md, session 44).
    uint i = grid_order[k];
    vec4 pi = particle_pos[i];
    neighbour_ref_pos[i] = pi;
    uint c = 0u;
    if (particle_vel[i].w != 0.0f) {  // static particles never move and get no force
      uint body_i = particle_body[i];
      // Impulse contacts: a particle whose slots were valid under the last build keeps them when
      // its list comes out as it was; only its old list is read back (the others' entries are
      // written blind: 13% of W1's build at 1 M on an H200).
      uint built = neighbour_state[MOTES_NEIGHBOUR_BUILDS] - 1u;  // the build was counted at its start
      bool tracked = (p.flags & MOTES_FLAG_IMPULSE) != 0u && i < p.rigid_particle_count &&
                     impulse_stamp[i] == built;
      uint old_count = tracked ? neighbour_count[i] : 0u;
      bool same = true;
      float support_i = neighbour_fluid_support(pi, i, p.fluid_first, p.fluid_count);
      GridWalk walk = grid_walk_begin(pi);
      uint lo, hi;
      while (grid_walk_next(walk, lo, hi)) {
        for (uint t = lo; t < hi; ++t) {
          uint j = grid_order[t];
          if (contact_skipped(body_i, sorted_body[t], i, j) ||
              !neighbour_within(pi, sorted_pos[t], p.neighbour_skin,
                                max(support_i, neighbour_fluid_support(sorted_pos[t], j, p.fluid_first,
                                                                p.fluid_count)))) {
            continue;
          }
          if (c < p.neighbour_capacity) {
            if (tracked && same) {  // read only while it can still match
              same = list_set(c, i, j);
            } else {
              list_put(c, i, j);
            }
          }
          ++c;
        }
      }
      if (tracked && neighbour_keeps_slots(old_count, c, same, p.neighbour_capacity)) {
        impulse_stamp[i] = built + 1u;
      }
    }
    neighbour_count[i] = c;
    if (c > p.neighbour_capacity) atomicAdd(group_over, 1u);
    atomicMax(group_most, c);
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u) {
    if (group_over != 0u) atomicAdd(neighbour_state[MOTES_NEIGHBOUR_OVER_CAPACITY], group_over);
    if (group_most != 0u) atomicMax(neighbour_state[MOTES_NEIGHBOUR_MAX_COUNT], group_most);
  }
}
