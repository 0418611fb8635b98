#version 450
// grid_build, pass 0: zero the T + 1 bucket counts (GridCellStart) that grid_build_count fills.
// A shader rather than vkCmdFillBuffer, so that a conditional rebuild can dispatch it indirectly.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"

void main() {
  uint i = thread_index();
  if (i <= p.table_mask + 1u) grid_cell_start[i] = 0u;
}
