// contacts_compute's shared pairs: a contact of two particles that list each other (both lists
// within capacity) is evaluated once, for the lower id, and both take it: the lower id its force,
// the higher id the same force negated (particle_contact_force is exactly antisymmetric when the
// contact laws are symmetric: every term is a product or a sum of negated inputs). Each particle
// still adds its terms in its list's order, so the sums are those of every particle evaluating
// its own list: a half list, with a deterministic gather instead of a scatter.
#include <cstdint>

#include "openmp_device.h"

namespace motes::openmp {

using shared::uint;

void OpenMPDevice::contact_pairs_index(const ContactInputs& in, std::size_t n, uint capacity) {
  const std::size_t slots = std::size_t{capacity} * n;
  if (contact_pair_id_.size() == slots) return;  // made for these lists already
  contact_pair_id_.assign(slots, kNoPair);
  contact_unpaired_.assign(n, 0u);
  std::vector<uint> owned(n + 1, 0u);
  uint* id = contact_pair_id_.data();
  uint* unpaired = contact_unpaired_.data();
  const auto rows = static_cast<std::int64_t>(n);
  // The slot m of i in the list of each partner j > i that lists it, kept as the slot's id for
  // now; the owned pairs counted.
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(rows))
  for (std::int64_t i = 0; i < rows; ++i) {
    const uint c = in.count[i];
    if (c > capacity) continue;
    uint pairs = 0;
    for (uint k = 0; k < c; ++k) {
      const uint j = in.list[std::size_t{k} * n + std::size_t(i)];
      const uint cj = in.count[j];
      if (j <= uint(i) || cj > capacity) continue;
      for (uint m = 0; m < cj; ++m) {
        if (in.list[std::size_t{m} * n + j] == uint(i)) {
          id[std::size_t{k} * n + std::size_t(i)] = m;
          ++pairs;
          break;
        }
      }
    }
    owned[std::size_t(i) + 1] = pairs;
  }
  for (std::size_t i = 0; i < n; ++i) owned[i + 1] += owned[i];  // where each owner's pairs start
  contact_pair_ends_.resize(owned[n]);
  contact_pairs_.resize(owned[n]);
  std::array<uint, 2>* ends = contact_pair_ends_.data();
  // Each owned slot and its partner's slot take the pair's number (each partner slot has one
  // owner: no two threads write it).
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(rows))
  for (std::int64_t i = 0; i < rows; ++i) {
    const uint c = in.count[i];
    if (c > capacity) continue;
    uint next = owned[std::size_t(i)];
    for (uint k = 0; k < c; ++k) {
      const std::size_t at = std::size_t{k} * n + std::size_t(i);
      const uint j = in.list[at];
      if (j <= uint(i) || id[at] == kNoPair) continue;
      id[std::size_t{id[at]} * n + j] = next;
      ends[next] = {uint(i), j};
      id[at] = next++;
    }
  }
  // The slots each particle evaluates itself.
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(rows))
  for (std::int64_t i = 0; i < rows; ++i) {
    const uint c = in.count[i];
    uint own = 0;
    for (uint k = 0; k < (c > capacity ? 0u : c); ++k) {
      own += id[std::size_t{k} * n + std::size_t(i)] == kNoPair ? 1u : 0u;
    }
    unpaired[i] = own;
  }
  contact_touched_.assign(n, 0u);
}

}  // namespace motes::openmp
