#version 450
// contacts_compute: every particle (one thread per particle id) gathers the forces of the
// particles overlapping it over the 27 neighbouring cells in the canonical order
// (docs/architecture.md), then the planes, and writes only its own force: no atomics, a fixed
// summation order. Same loop structure as backends/openmp/contacts_compute.cpp. Threads go in
// particle order (neighbours in space share the rows of cells they read; no scattered write), as
// in backends/cuda/contacts_compute.cu.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/contact_force.h"
#include "shared/grid_hash.h"

// Adds the forces of sorted slots [lo, hi) on the particle (xi, ui, radius, inverse mass).
void gather_range(uint lo, uint hi, vec3 xi, vec3 ui, vec4 pi, float inv_mi, uint body_i,
                  uint law_base, inout vec3 f) {
  for (uint t = lo; t < hi; ++t) {
    vec4 pj = sorted_pos[t];
    float dx = pj.x - pi.x;
    float dy = pj.y - pi.y;
    float dz = pj.z - pi.z;
    float rsum = pi.w + pj.w;
    if (dx * dx + dy * dy + dz * dz >= rsum * rsum || sorted_body[t] == body_i) continue;
    vec4 vj = sorted_vel[t];
    f += particle_contact_force(xi, ui, pi.w, inv_mi, xyz(pj), xyz(vj), pj.w, vj.w,
                                contact_laws[law_base + sorted_material[t]], p.flags);
  }
}

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  vec4 pi = particle_pos[i];
  vec4 vi = particle_vel[i];
  if (vi.w == 0.0f) {  // static particle: its force is never used
    particle_force[i] = vec4(0.0f);
    return;
  }
  vec3 xi = xyz(pi);
  vec3 ui = xyz(vi);
  uint body_i = particle_body[i];
  uint law_base = particle_material[i] * p.material_count;
  uint mask = p.table_mask;
  int cx = grid_cell_coord(pi.x, p.inv_cell_size);
  int cy = grid_cell_coord(pi.y, p.inv_cell_size);
  int cz = grid_cell_coord(pi.z, p.inv_cell_size);

  vec3 f = vec3(0.0f);
  uint centres[9];
  int row = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      uint c = grid_bucket(cx, cy + dy, cz + dz, mask);
      // Hashed rows can share buckets; every bucket is visited once, by its first row.
      bool clash = false;
      for (int r = 0; r < row; ++r) clash = clash || ((c - centres[r] + 2u) & mask) <= 4u;
      centres[row] = c;
      if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
        gather_range(grid_cell_start[c - 1u], grid_cell_start[c + 2u], xi, ui, pi, vi.w, body_i,
                     law_base, f);
      } else {
        for (uint k = 0u; k < 3u; ++k) {
          uint b = (c + k - 1u) & mask;
          bool seen = false;
          for (int r = 0; r < row; ++r) seen = seen || grid_row_covers(centres[r], b, mask);
          if (!seen) {
            gather_range(grid_cell_start[b], grid_cell_start[b + 1u], xi, ui, pi, vi.w, body_i,
                         law_base, f);
          }
        }
      }
      ++row;
    }
  }
  for (uint k = 0u; k < p.plane_count; ++k) {
    PlaneData pl = planes[k];
    f += plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset,
                             contact_laws[law_base + pl.material], p.flags);
  }
  particle_force[i] = vec4(f, 0.0f);
}
