#version 450
// constraints_relax: p.constraint_sweeps sweeps over the p.constraint_count colours of
// ConstraintColours in one workgroup, each colour as constraints_solve.comp does it (its
// constraints strided over the workgroup's threads), a barrier between colours; with
// MOTES_FLAG_SKIN_CHECK the last sweep asks for a rebuild when a particle it moved is too far
// from where the lists were built. As backends/openmp/constraints_relax.cpp.
#extension GL_GOOGLE_include_directive : require
// The threads read what the others wrote in the colour before: the particles' buffers coherent.
#define MOTES_PARTICLES_COHERENT
#include "kernel_common.glsl"
#include "shared/neighbours.h"

shared uint group_moved;

void main() {
  uint t = gl_LocalInvocationID.x;
  if (t == 0u) group_moved = 0u;
  float inv_dt = 1.0f / p.gravity_dt.w;
  bool moved = false;
  for (uint sweep = 0u; sweep < p.constraint_sweeps; ++sweep) {
    bool check = (p.flags & MOTES_FLAG_SKIN_CHECK) != 0u && sweep + 1u == p.constraint_sweeps;
    for (uint colour = 0u; colour < p.constraint_count; ++colour) {
      uint end = constraint_colours[colour + 1u];
      for (uint k = constraint_colours[colour] + t; k < end; k += WORKGROUP_SIZE) {
        Constraint c = constraints[k];
        vec4 xa = particle_pos[c.a];
        vec4 xb = particle_pos[c.b];
        vec4 va = particle_vel[c.a];
        vec4 vb = particle_vel[c.b];
        constraint_project(xa, xb, va, vb, c, inv_dt);
        particle_pos[c.a] = xa;
        particle_pos[c.b] = xb;
        particle_vel[c.a] = va;
        particle_vel[c.b] = vb;
        if (check && (neighbour_moved_too_far(xa, neighbour_ref_pos[c.a], p.neighbour_skin) ||
                      neighbour_moved_too_far(xb, neighbour_ref_pos[c.b], p.neighbour_skin))) {
          moved = true;
        }
      }
      memoryBarrierBuffer();
      barrier();
    }
  }
  if (moved) atomicOr(group_moved, 1u);
  barrier();
  if (t == 0u && group_moved != 0u) neighbour_state[MOTES_NEIGHBOUR_REBUILD] = 1u;
}
