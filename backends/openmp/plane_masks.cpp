// plane_masks: the planes each particle may touch before the next list build, for
// contacts_compute. Between two builds no particle moves 0.45 skin from where the lists were
// built (NeighbourRefPos: shared/neighbours.h, neighbour_moved_too_far), so a plane whose gap at
// the build is at least r + |n| skin stays out of reach: plane_contact_force would give it exactly
// 0 (overlap <= 0), and skipping it leaves every force bit for bit as it was (a force sum starts
// at +0 and so never is -0, which adding +0 would change). A gap that is not a number keeps the
// plane. With no skin the lists are made every step where the particles are: the test is then
// the force's own (gap < r).
#include <cstdint>
#include <new>

#include "openmp_device.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

const std::uint32_t* OpenMPDevice::plane_masks(const shared::StepParams& p, const vec4* ref) {
  if (!plane_masks_on_ || p.plane_count == 0 || p.plane_count > 32) return nullptr;
  const auto n = static_cast<std::int64_t>(p.particle_count);
  if (!plane_masks_ready_) {
    try {
      plane_masks_.resize(p.particle_count);
    } catch (const std::bad_alloc&) {
      plane_masks_ = {};
      return nullptr;
    }
    const shared::PlaneData* planes = buf<shared::PlaneData>(Buffer::Planes);
    float reach[32];  // how far beyond r a plane may still be touched
    for (uint k = 0; k < p.plane_count; ++k) {
      const shared::vec3 normal = shared::xyz(planes[k].normal_offset);
      reach[k] = p.neighbour_skin * shared::length(normal);
    }
    std::uint32_t* mask = plane_masks_.data();
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n))
    for (std::int64_t i = 0; i < n; ++i) {
      const vec4 at = ref[i];
      std::uint32_t m = 0;
      for (uint k = 0; k < p.plane_count; ++k) {
        const vec4 no = planes[k].normal_offset;
        const float gap = shared::dot(shared::xyz(no), shared::xyz(at)) - no.w;
        if (!(gap >= at.w + reach[k])) m |= std::uint32_t{1} << k;
      }
      mask[i] = m;
    }
    plane_masks_ready_ = true;
  }
  return plane_masks_.data();
}

}  // namespace motes::openmp
