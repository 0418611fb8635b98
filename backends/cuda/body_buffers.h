// The buffers of the three body passes (body_passes.cuh), gathered for a kernel launch.
#pragma once

#include "shared/common.h"

namespace motes::cuda {

/// Every buffer the body passes touch.
struct BodyBuffers {
  const shared::uint* __restrict__ first;
  const shared::uint* __restrict__ particle_body;
  const shared::vec4* __restrict__ local;
  const shared::vec4* __restrict__ force;
  shared::vec4* pos;  // ParticlePos: read by the reduce, written by the update
  shared::vec4* vel;
  shared::vec4* body_pos;
  shared::vec4* quat;
  shared::vec4* body_vel;
  shared::vec4* angmom;
  shared::vec4* angvel;
  const shared::vec4* __restrict__ inv_inertia;
  shared::vec4* body_force;
  shared::vec4* body_torque;
  const shared::vec4* __restrict__ ref;  // NeighbourRefPos
  shared::uint* state;                   // NeighbourState
};

}  // namespace motes::cuda
