#version 450
// grid_build, pass 3 of 5 (once per level, top down): adds each block's scanned offset (from the
// level above, in scan_scratch at args.w) to every value of the block. Same args as scan_block.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"

void main() {
  uint i = thread_index();
  if (i >= args.z) return;
  uint add = scan_scratch[args.w + i / uint(SCAN_BLOCK)];
  if (args.x == 0u) {
    grid_cell_start[i] += add;
  } else {
    scan_scratch[args.y + i] += add;
  }
}
