// The buffers of a halo body entry (shared/halo.h), for halo_pack and halo_unpack.
#pragma once

#include "motes/backend/device.h"
#include "shared/halo.h"

namespace motes::openmp {

/// A rigid body entry's buffers, in HaloData's order.
constexpr Buffer kHaloBodyState[MOTES_HALO_BODY_VEC4S] = {
    Buffer::BodyPos, Buffer::BodyQuat, Buffer::BodyVel, Buffer::BodyAngMom, Buffer::BodyAngVel};

}  // namespace motes::openmp
