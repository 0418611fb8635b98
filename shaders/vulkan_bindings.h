// Descriptor bindings of the Vulkan backend: one set, binding k = motes::Buffer k, then the
// backend's own scratch buffers. Valid C++ and GLSL; vulkan_device.cpp static_asserts that the
// numbers match the Buffer enum.
#ifndef MOTES_VULKAN_BINDINGS_H
#define MOTES_VULKAN_BINDINGS_H

#define B_PARTICLE_POS 0
#define B_PARTICLE_VEL 1
#define B_PARTICLE_LOCAL 2
#define B_PARTICLE_BODY 3
#define B_PARTICLE_MATERIAL 4
#define B_PARTICLE_FORCE 5
#define B_BODY_POS 6
#define B_BODY_QUAT 7
#define B_BODY_VEL 8
#define B_BODY_ANGMOM 9
#define B_BODY_ANGVEL 10
#define B_BODY_INV_INERTIA 11
#define B_BODY_FORCE 12
#define B_BODY_TORQUE 13
#define B_BODY_FIRST 14
#define B_GRID_BUCKET 15
#define B_GRID_ORDER 16
#define B_GRID_CELL_START 17
#define B_SORTED_POS 18
#define B_SORTED_BODY 19
#define B_NEIGHBOUR_LIST 20
#define B_NEIGHBOUR_COUNT 21
#define B_NEIGHBOUR_REF_POS 22
#define B_NEIGHBOUR_STATE 23
#define B_CONTACT_LAWS 24
#define B_PLANES 25
#define B_CONSTRAINTS 26
#define B_CONSTRAINT_COLOURS 27
#define B_LINK_EXCLUSIONS 28
#define B_CLUSTERS 29
#define B_CLUSTER_MEMBERS 30
#define B_CLUSTER_FRAMES 31
#define B_CLUSTER_GATHER 32
#define B_PARTICLE_MOMENT 33
#define B_BODY_VEL_START 34
#define B_BODY_ANGVEL_START 35
#define B_BODY_VEL_PUSH 36
#define B_BODY_ANGMOM_PUSH 37
#define B_CONTACT_IMPULSE 38
#define B_IMPULSE_STAMP 39
#define B_MOTION_CHECK 40
#define B_ENERGY_PARTIALS 41
#define B_HALO_INDEX 42
#define B_HALO_DATA 43
#define B_PARTITION_REF_POS 44
#define B_PARTITION_CHECK 45
#define B_CONTACT_IMPULSE_SPLIT 46
#define B_BODY_POS_LOW 47
#define B_FLUID_STATE 48
#define B_FLUID_MATERIALS 49
#define B_FLUID_VEL_OLD 50
#define B_FLUID_AUX 51
#define B_FLUID_NORMAL 52
// Scratch buffers of the backend (not part of motes::Buffer).
#define B_GRID_ARRIVAL 53  // uint (N): arrival rank of a particle in its bucket (atomic, any order)
#define B_GRID_UNSORTED 54  // uint (N): particle ids grouped by bucket, in arrival order
#define B_SCAN_SCRATCH 55   // uint: block sums of every level of the bucket-count scan
// uint: VkDispatchIndirectCommand (4 words each) of every pass of a conditional rebuild, then the
// same for when it runs (written once at allocate), then the rebuild's gate word (1: this step
// rebuilds). neighbours_update.comp sets the gate word (which conditional rendering reads), and
// where the passes are dispatched indirectly (a device without conditional rendering:
// neighbours_update.cpp) copies or zeroes the first; neighbours_update_small.glsl sets the gate
// word only (its neighbours_build reads it).
#define B_INDIRECT_ARGS 56
// uint: the neighbour list's column blocks after the first (B_NEIGHBOUR_LIST), when one buffer
// cannot hold every column (maxStorageBufferRange): block b holds columns [b C, (b + 1) C) with
// C = StepParams::neighbour_columns (kernel_common.glsl: list_entry).
#define B_NEIGHBOUR_LIST_1 57
#define B_NEIGHBOUR_LIST_2 58
#define B_NEIGHBOUR_LIST_3 59
#define NEIGHBOUR_LIST_BLOCKS 4
#define B_COUNT 60

// Threads per workgroup of every kernel; the scan handles 4 elements per thread.
#define WORKGROUP_SIZE 256
#define SCAN_BLOCK 1024

#endif  // MOTES_VULKAN_BINDINGS_H
