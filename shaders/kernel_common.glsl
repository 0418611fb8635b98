// Included by every compute shader of the Vulkan backend: the shared physics headers, launch
// parameters, every buffer of the single descriptor set, and the flat thread index.
#ifndef MOTES_KERNEL_COMMON_GLSL
#define MOTES_KERNEL_COMMON_GLSL

#include "shared/common.h"
#include "shared/links.h"
#include "shared/params.h"
#include "shared/shape_matching.h"
#include "shared/impulse.h"
#include "shared/fluid.h"
#include "vulkan_bindings.h"

// A shader whose workgroup size is set when its pipeline is made (specialization constant 0:
// neighbours_update_small.glsl) defines MOTES_LOCAL_SIZE_SPECIALIZED first; WORKGROUP_SIZE is
// then only the default.
#ifdef MOTES_LOCAL_SIZE_SPECIALIZED
layout(local_size_x = WORKGROUP_SIZE, local_size_x_id = 0) in;
#else
layout(local_size_x = WORKGROUP_SIZE) in;
#endif

// StepParams travels with every dispatch; args are the pass's own values (scan levels).
layout(push_constant) uniform Push {
  StepParams p;
  uvec4 args;
};

// Every binding is a buffer of its own (VulkanDevice::allocate), so every buffer is declared
// restrict: a store through one changes nothing another reads, and the driver may keep loads in
// flight across stores. A shader that writes none of the particles' positions and velocities, the
// grid and the neighbour lists (the force law, shaders/contacts_compute.glsl; the liquid's sums,
// impulses_compute and impulses_apply, the bodies' sums, the clusters' fits, the halo's packing,
// the displacement, energy and motion checks) defines MOTES_STATE_READONLY first: those buffers
// are then readonly too, which lets NVIDIA's driver load them through the read-only data cache,
// as CUDA's const __restrict__ pointers.
// A shader whose threads read, after a barrier, particles that other threads of its workgroup
// wrote (constraints_relax.comp) defines MOTES_PARTICLES_COHERENT first; one whose threads so
// read the grid's buckets, bucket starts and unsorted slots (the one-workgroup grid build,
// neighbours_update_small.glsl) defines MOTES_GRID_COHERENT.
#if defined(MOTES_STATE_READONLY) && (defined(MOTES_PARTICLES_COHERENT) || defined(MOTES_GRID_COHERENT))
#error "MOTES_STATE_READONLY excludes MOTES_PARTICLES_COHERENT and MOTES_GRID_COHERENT"
#endif
#ifdef MOTES_STATE_READONLY
#define MOTES_STATE_ACCESS readonly
#else
#define MOTES_STATE_ACCESS
#endif
#ifdef MOTES_PARTICLES_COHERENT
#define MOTES_PARTICLES_ACCESS coherent
#else
#define MOTES_PARTICLES_ACCESS MOTES_STATE_ACCESS
#endif
#ifdef MOTES_GRID_COHERENT
#define MOTES_GRID_ACCESS coherent
#define MOTES_GRID_SLOTS_ACCESS coherent
#else
#define MOTES_GRID_ACCESS MOTES_STATE_ACCESS
#define MOTES_GRID_SLOTS_ACCESS
#endif
layout(std430, binding = B_PARTICLE_POS) MOTES_PARTICLES_ACCESS restrict buffer ParticlePosBuf {
  vec4 particle_pos[];
};
layout(std430, binding = B_PARTICLE_VEL) MOTES_PARTICLES_ACCESS restrict buffer ParticleVelBuf {
  vec4 particle_vel[];
};
layout(std430, binding = B_PARTICLE_LOCAL) readonly restrict buffer ParticleLocalBuf { vec4 particle_local[]; };
layout(std430, binding = B_PARTICLE_BODY) readonly restrict buffer ParticleBodyBuf { uint particle_body[]; };
layout(std430, binding = B_PARTICLE_MATERIAL) readonly restrict buffer ParticleMaterialBuf { uint particle_material[]; };
layout(std430, binding = B_PARTICLE_FORCE) restrict buffer ParticleForceBuf { vec4 particle_force[]; };
layout(std430, binding = B_BODY_POS) restrict buffer BodyPosBuf { vec4 body_pos[]; };
layout(std430, binding = B_BODY_QUAT) restrict buffer BodyQuatBuf { vec4 body_quat[]; };
layout(std430, binding = B_BODY_VEL) restrict buffer BodyVelBuf { vec4 body_vel[]; };
layout(std430, binding = B_BODY_ANGMOM) restrict buffer BodyAngMomBuf { vec4 body_angmom[]; };
layout(std430, binding = B_BODY_ANGVEL) restrict buffer BodyAngVelBuf { vec4 body_angvel[]; };
layout(std430, binding = B_BODY_INV_INERTIA) readonly restrict buffer BodyInvInertiaBuf { vec4 body_inv_inertia[]; };
layout(std430, binding = B_BODY_FORCE) restrict buffer BodyForceBuf { vec4 body_force[]; };
layout(std430, binding = B_BODY_TORQUE) restrict buffer BodyTorqueBuf { vec4 body_torque[]; };
layout(std430, binding = B_BODY_FIRST) readonly restrict buffer BodyFirstBuf { uint body_first[]; };
layout(std430, binding = B_GRID_BUCKET) MOTES_GRID_ACCESS restrict buffer GridBucketBuf { uint grid_bucket_of[]; };
layout(std430, binding = B_GRID_ORDER) MOTES_STATE_ACCESS restrict buffer GridOrderBuf { uint grid_order[]; };
layout(std430, binding = B_GRID_CELL_START) MOTES_GRID_ACCESS restrict buffer GridCellStartBuf { uint grid_cell_start[]; };
layout(std430, binding = B_SORTED_POS) MOTES_STATE_ACCESS restrict buffer SortedPosBuf { vec4 sorted_pos[]; };
layout(std430, binding = B_SORTED_BODY) MOTES_STATE_ACCESS restrict buffer SortedBodyBuf { uint sorted_body[]; };
layout(std430, binding = B_NEIGHBOUR_LIST) MOTES_STATE_ACCESS restrict buffer NeighbourListBuf { uint neighbour_list[]; };
layout(std430, binding = B_NEIGHBOUR_LIST_1) MOTES_STATE_ACCESS restrict buffer NeighbourList1Buf { uint neighbour_list_1[]; };
layout(std430, binding = B_NEIGHBOUR_LIST_2) MOTES_STATE_ACCESS restrict buffer NeighbourList2Buf { uint neighbour_list_2[]; };
layout(std430, binding = B_NEIGHBOUR_LIST_3) MOTES_STATE_ACCESS restrict buffer NeighbourList3Buf { uint neighbour_list_3[]; };
layout(std430, binding = B_NEIGHBOUR_COUNT) MOTES_STATE_ACCESS restrict buffer NeighbourCountBuf { uint neighbour_count[]; };
layout(std430, binding = B_NEIGHBOUR_REF_POS) MOTES_STATE_ACCESS restrict buffer NeighbourRefPosBuf { vec4 neighbour_ref_pos[]; };
layout(std430, binding = B_NEIGHBOUR_STATE) restrict buffer NeighbourStateBuf { uint neighbour_state[]; };
layout(std430, binding = B_CONTACT_LAWS) readonly restrict buffer ContactLawsBuf { ContactLaw contact_laws[]; };
layout(std430, binding = B_PLANES) readonly restrict buffer PlanesBuf { PlaneData planes[]; };
layout(std430, binding = B_CONSTRAINTS) readonly restrict buffer ConstraintsBuf { Constraint constraints[]; };
layout(std430, binding = B_CONSTRAINT_COLOURS) readonly restrict buffer ConstraintColoursBuf {
  uint constraint_colours[];
};
layout(std430, binding = B_CLUSTERS) readonly restrict buffer ClustersBuf { Cluster clusters[]; };
layout(std430, binding = B_CLUSTER_MEMBERS) readonly restrict buffer ClusterMembersBuf { ClusterMember cluster_members[]; };
layout(std430, binding = B_CLUSTER_FRAMES) restrict buffer ClusterFramesBuf { ClusterFrame cluster_frames[]; };
layout(std430, binding = B_CLUSTER_GATHER) readonly restrict buffer ClusterGatherBuf { uint cluster_gather[]; };
layout(std430, binding = B_PARTICLE_MOMENT) restrict buffer ParticleMomentBuf { vec4 particle_moment[]; };
layout(std430, binding = B_BODY_VEL_START) restrict buffer BodyVelStartBuf { vec4 body_vel_start[]; };
layout(std430, binding = B_BODY_ANGVEL_START) restrict buffer BodyAngVelStartBuf { vec4 body_angvel_start[]; };
layout(std430, binding = B_CONTACT_IMPULSE) restrict buffer ContactImpulseBuf { vec4 contact_impulse_acc[]; };
layout(std430, binding = B_CONTACT_IMPULSE_SPLIT) restrict buffer ContactImpulseSplitBuf {
  vec4 contact_impulse_split[];
};
layout(std430, binding = B_IMPULSE_STAMP) restrict buffer ImpulseStampBuf { uint impulse_stamp[]; };
layout(std430, binding = B_BODY_POS_LOW) restrict buffer BodyPosLowBuf { vec4 body_pos_low[]; };
layout(std430, binding = B_MOTION_CHECK) restrict buffer MotionCheckBuf { uint motion_check[]; };
layout(std430, binding = B_LINK_EXCLUSIONS) readonly restrict buffer LinkExclusionsBuf { uint link_exclusions[]; };
layout(std430, binding = B_HALO_INDEX) readonly restrict buffer HaloIndexBuf { uint halo_index[]; };
layout(std430, binding = B_HALO_DATA) restrict buffer HaloDataBuf { vec4 halo_data[]; };
layout(std430, binding = B_PARTITION_REF_POS) readonly restrict buffer PartitionRefPosBuf { vec4 partition_ref_pos[]; };
layout(std430, binding = B_PARTITION_CHECK) restrict buffer PartitionCheckBuf { uint partition_check[]; };
layout(std430, binding = B_BODY_VEL_PUSH) restrict buffer BodyVelPushBuf { vec4 body_vel_push[]; };
layout(std430, binding = B_BODY_ANGMOM_PUSH) restrict buffer BodyAngMomPushBuf { vec4 body_angmom_push[]; };
layout(std430, binding = B_ENERGY_PARTIALS) restrict buffer EnergyPartialsBuf { uint energy_partials[]; };
layout(std430, binding = B_FLUID_STATE) restrict buffer FluidStateBuf { vec4 fluid_state[]; };
layout(std430, binding = B_FLUID_MATERIALS) readonly restrict buffer FluidMaterialsBuf {
  FluidMaterial fluid_materials[];
};
layout(std430, binding = B_FLUID_VEL_OLD) restrict buffer FluidVelOldBuf { vec4 fluid_vel_old[]; };
layout(std430, binding = B_FLUID_AUX) restrict buffer FluidAuxBuf { vec4 fluid_aux[]; };
layout(std430, binding = B_FLUID_NORMAL) restrict buffer FluidNormalBuf { vec4 fluid_normal[]; };
layout(std430, binding = B_GRID_ARRIVAL) restrict buffer GridArrivalBuf { uint grid_arrival[]; };
layout(std430, binding = B_GRID_UNSORTED) MOTES_GRID_SLOTS_ACCESS restrict buffer GridUnsortedBuf { uint grid_unsorted[]; };
layout(std430, binding = B_SCAN_SCRATCH) restrict buffer ScanScratchBuf { uint scan_scratch[]; };
layout(std430, binding = B_INDIRECT_ARGS) restrict buffer IndirectArgsBuf { uint indirect_args[]; };

// Entry k of particle i's neighbour list (entry k at k N + i of the whole list). A list too large
// for one storage buffer is split into column blocks of p.neighbour_columns columns (0: one block),
// bound as B_NEIGHBOUR_LIST, then _1 to _3.
uint list_block(uint k) {  // comparisons, not a division: this is on every neighbour's path
  uint c = p.neighbour_columns;
  if (c == 0u || k < c) return 0u;
  return k < 2u * c ? 1u : (k < 3u * c ? 2u : 3u);
}

uint list_entry(uint k, uint i) {
  uint b = list_block(k);
  uint at = (k - b * p.neighbour_columns) * p.particle_count + i;
  if (b == 0u) return neighbour_list[at];
  if (b == 1u) return neighbour_list_1[at];
  if (b == 2u) return neighbour_list_2[at];
  return neighbour_list_3[at];
}

#ifndef MOTES_STATE_READONLY
// Sets entry k of particle i to j; returns whether it was j already.
bool list_set(uint k, uint i, uint j) {
  uint b = list_block(k);
  uint at = (k - b * p.neighbour_columns) * p.particle_count + i;
  uint was;
  if (b == 0u) {
    was = neighbour_list[at];
    neighbour_list[at] = j;
  } else if (b == 1u) {
    was = neighbour_list_1[at];
    neighbour_list_1[at] = j;
  } else if (b == 2u) {
    was = neighbour_list_2[at];
    neighbour_list_2[at] = j;
  } else {
    was = neighbour_list_3[at];
    neighbour_list_3[at] = j;
  }
  return was == j;
}

// Sets entry k of particle i to j, without reading it.
void list_put(uint k, uint i, uint j) {
  uint b = list_block(k);
  uint at = (k - b * p.neighbour_columns) * p.particle_count + i;
  if (b == 0u) {
    neighbour_list[at] = j;
  } else if (b == 1u) {
    neighbour_list_1[at] = j;
  } else if (b == 2u) {
    neighbour_list_2[at] = j;
  } else {
    neighbour_list_3[at] = j;
  }
}
#endif  // MOTES_STATE_READONLY

// Workgroups beyond 65,535 are dispatched as a 2D grid (x, y); this is the flat index.
uint flat_group() { return gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x; }
uint thread_index() { return flat_group() * WORKGROUP_SIZE + gl_LocalInvocationID.x; }

#endif  // MOTES_KERNEL_COMMON_GLSL
