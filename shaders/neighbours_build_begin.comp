#version 450
// neighbours_build, pass 1 of 2 (one invocation): the build starts in NeighbourState.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/neighbours.h"
#include "neighbours_start.glsl"

void main() {
  if (thread_index() == 0u) neighbours_start();
}
