#version 450
// halo_pack: the state a neighbour rank holds copies of, gathered into HaloData (shared/halo.h):
// one thread per entry, the particle entries first, then the rigid body entries. Plain copies of
// whole vec4s, so the bits are those of every other backend.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY  // writes no particle position, velocity, grid or list
#include "kernel_common.glsl"
#include "shared/halo.h"

void main() {
  uint t = thread_index();
  uint np = p.halo_particles;
  if (t >= np + p.halo_bodies) return;
  uint i = halo_index[p.halo_first + t];
  if (t < np) {
    if (i >= p.particle_count) return;  // not a particle: the entry is left as it is
    halo_data[MOTES_HALO_PARTICLE_VEC4S * t] = particle_pos[i];
    halo_data[MOTES_HALO_PARTICLE_VEC4S * t + 1u] = particle_vel[i];
    return;
  }
  if (i >= p.body_count) return;
  uint at = MOTES_HALO_PARTICLE_VEC4S * np + MOTES_HALO_BODY_VEC4S * (t - np);
  halo_data[at] = body_pos[i];
  halo_data[at + 1u] = body_quat[i];
  halo_data[at + 2u] = body_vel[i];
  halo_data[at + 3u] = body_angmom[i];
  halo_data[at + 4u] = body_angvel[i];
}
