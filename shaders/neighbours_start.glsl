// The start of a neighbour-list build in NeighbourState: no rebuild pending, one more build, and
// the figures of this build from zero (neighbours_build adds to them with atomics). Run by one
// invocation: neighbours_build_begin.comp before a build on its own, neighbours_update.comp before a
// conditional one. Needs kernel_common.glsl and shared/neighbours.h.
#ifndef MOTES_NEIGHBOURS_START_GLSL
#define MOTES_NEIGHBOURS_START_GLSL

void neighbours_start() {
  neighbour_state[MOTES_NEIGHBOUR_REBUILD] = 0u;
  neighbour_state[MOTES_NEIGHBOUR_BUILDS] += 1u;
  neighbour_state[MOTES_NEIGHBOUR_OVER_CAPACITY] = 0u;
  neighbour_state[MOTES_NEIGHBOUR_MAX_COUNT] = 0u;
}

#endif  // MOTES_NEIGHBOURS_START_GLSL
