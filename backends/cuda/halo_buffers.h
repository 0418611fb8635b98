// The buffers of a halo entry (shared/halo.h), gathered for the launches of halo_pack and
// halo_unpack.
#pragma once

#include "shared/common.h"
#include "shared/halo.h"

namespace motes::cuda {

/// A rigid body entry's state, in HaloData's order: BodyPos, BodyQuat, BodyVel, BodyAngMom,
/// BodyAngVel.
struct HaloBodies {
  shared::vec4* state[MOTES_HALO_BODY_VEC4S];
};

}  // namespace motes::cuda
