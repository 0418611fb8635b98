// The contact law of every pair of materials (the ContactLaws buffer).
#pragma once

#include <vector>

#include "motes/scene.h"
#include "shared/params.h"

namespace motes {

/// Pair (a, b) at a * M + b: stiffness, damping and tangential are the arithmetic means of the two
/// materials' values; friction is the smaller cap (no cap counts as infinite).
std::vector<shared::ContactLaw> contact_law_table(const std::vector<Material>& materials);

}  // namespace motes
