// What several oracle files share, beside reference.h's contracts (not part of the oracle's
// interface: included by the oracle's own files only).
#pragma once

#include <vector>

#include "reference.h"
#include "shared/halo.h"

namespace motes_ref {

/// The body state of a halo body entry, in HaloData's order (halo_pack, halo_unpack).
inline constexpr std::vector<vec4> Bodies::*kBodyState[MOTES_HALO_BODY_VEC4S] = {
    &Bodies::pos, &Bodies::quat, &Bodies::vel, &Bodies::angmom, &Bodies::angvel};

}  // namespace motes_ref
