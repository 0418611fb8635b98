#version 450
// halo_unpack: HaloData's entries scattered to the particles and rigid bodies HaloIndex names
// (shared/halo.h), one thread per entry; a neighbour-list rebuild is asked for when a particle it
// wrote is too far from its NeighbourRefPos (one store per workgroup at most).
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/halo.h"
#include "shared/neighbours.h"

shared uint group_moved;

void main() {
  uint t = thread_index();
  uint np = p.halo_particles;
  if (gl_LocalInvocationID.x == 0u) group_moved = 0u;
  barrier();
  if (t < np + p.halo_bodies) {
    uint i = halo_index[p.halo_first + t];
    if (t < np) {
      if (i < p.particle_count) {  // otherwise not a particle: nothing written
        vec4 x = halo_data[MOTES_HALO_PARTICLE_VEC4S * t];
        particle_pos[i] = x;
        particle_vel[i] = halo_data[MOTES_HALO_PARTICLE_VEC4S * t + 1u];
        if (neighbour_moved_too_far(x, neighbour_ref_pos[i], p.neighbour_skin)) {
          atomicOr(group_moved, 1u);
        }
      }
    } else if (i < p.body_count) {
      uint at = MOTES_HALO_PARTICLE_VEC4S * np + MOTES_HALO_BODY_VEC4S * (t - np);
      body_pos[i] = halo_data[at];
      body_quat[i] = halo_data[at + 1u];
      body_vel[i] = halo_data[at + 2u];
      body_angmom[i] = halo_data[at + 3u];
      body_angvel[i] = halo_data[at + 4u];
    }
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u && group_moved != 0u) {
    neighbour_state[MOTES_NEIGHBOUR_REBUILD] = 1u;
  }
}
