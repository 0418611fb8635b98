#version 450
// constraints_solve: one colour of distance constraints (no two share a particle), one thread per
// constraint (shared/links.h), and with MOTES_FLAG_SKIN_CHECK (the last sweep) a neighbour-list
// rebuild asked for when a particle it moved is too far from where the lists were built (one
// store per workgroup at most); as backends/openmp/constraints_solve.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/neighbours.h"

shared uint group_moved;

void main() {
  uint k = thread_index();
  if (gl_LocalInvocationID.x == 0u) group_moved = 0u;
  barrier();
  if (k < p.constraint_count) {
    Constraint c = constraints[p.constraint_first + k];
    vec4 xa = particle_pos[c.a];
    vec4 xb = particle_pos[c.b];
    vec4 va = particle_vel[c.a];
    vec4 vb = particle_vel[c.b];
    constraint_project(xa, xb, va, vb, c, 1.0f / p.gravity_dt.w);
    particle_pos[c.a] = xa;
    particle_pos[c.b] = xb;
    particle_vel[c.a] = va;
    particle_vel[c.b] = vb;
    if ((p.flags & MOTES_FLAG_SKIN_CHECK) != 0u &&
        (neighbour_moved_too_far(xa, neighbour_ref_pos[c.a], p.neighbour_skin) ||
         neighbour_moved_too_far(xb, neighbour_ref_pos[c.b], p.neighbour_skin))) {
      atomicOr(group_moved, 1u);
    }
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u && group_moved != 0u) {
    neighbour_state[MOTES_NEIGHBOUR_REBUILD] = 1u;
  }
}
