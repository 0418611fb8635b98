#version 450
// neighbours_update, pass 0 (one workgroup): when NeighbourState asks for a rebuild, the gate word
// (args.z) is set to 1 (0 otherwise) and the build starts (neighbours_start); the arguments of the
// rebuild's indirect passes (args.x words: none where conditional rendering gates the passes) are
// copied from the template written at allocate (from args.y), or zeroed, so that the passes do
// nothing.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/neighbours.h"
#include "neighbours_start.glsl"

shared bool rebuild_now;

void main() {
  if (gl_LocalInvocationID.x == 0u) rebuild_now = neighbour_state[MOTES_NEIGHBOUR_REBUILD] != 0u;
  barrier();
  bool rebuild = rebuild_now;
  for (uint w = gl_LocalInvocationID.x; w < args.x; w += uint(WORKGROUP_SIZE)) {
    indirect_args[w] = rebuild ? indirect_args[args.y + w] : 0u;
  }
  if (gl_LocalInvocationID.x == 0u) {
    indirect_args[args.z] = rebuild ? 1u : 0u;
    if (rebuild) neighbours_start();
  }
}
