#version 450
// neighbours_update for small grids, one workgroup (shaders/neighbours_update_small.glsl), on
// devices without subgroup arithmetic: its scan of the bucket counts in shared memory.
#extension GL_GOOGLE_include_directive : require
#include "neighbours_update_small.glsl"
