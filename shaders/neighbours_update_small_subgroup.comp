#version 450
// neighbours_update for small grids, one workgroup (shaders/neighbours_update_small.glsl), on
// devices with subgroup arithmetic (chosen at device creation, as grid_build_scan_block_subgroup
// is): its scan of the bucket counts reads them a subgroup's width at a time.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define MOTES_SMALL_SUBGROUP_SCAN
#include "neighbours_update_small.glsl"
