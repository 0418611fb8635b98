// contacts_compute's shared pairs: a contact of two particles that list each other (both lists
// within capacity) is evaluated once, for the lower id, and both take it: the lower id its force,
// the higher id the same force negated (particle_contact_force is exactly antisymmetric when the
// contact laws are symmetric: every term is a product or a sum of negated inputs). Each term goes
// to its list slot, and each particle adds its slots in its list's order, so the sums are those of
// every particle evaluating its own list: a half list, with a deterministic gather instead of a
// scatter. The slots are stored particle by particle (contact_slot_first_), so the gather streams.
#include <cstdint>
#include <limits>

#include "openmp_device.h"

namespace motes::openmp {

using shared::uint;

bool OpenMPDevice::contact_pairs_index(const ContactInputs& in, std::size_t n, uint capacity) {
  if (contact_pairs_ready_) return true;  // made for these lists already
  const auto rows = static_cast<std::int64_t>(n);
  const auto listed = [&](std::size_t i) {
    const uint c = in.count[i];
    return c <= capacity ? c : 0u;
  };
  // Where each particle's slots start (over capacity: none, it walks the grid).
  std::vector<std::uint64_t> first(n + 1, 0u);
  for (std::size_t i = 0; i < n; ++i) first[i + 1] = first[i] + listed(i);
  if (first[n] > std::numeric_limits<uint>::max()) return false;
  contact_slot_first_.assign(first.begin(), first.end());
  const uint* at = contact_slot_first_.data();
  // For each slot of i whose partner j > i lists i: the slot of i in j's list; owned pairs counted.
  std::vector<uint> mirror(first[n], kNoPair);
  std::vector<uint> owned(n + 1, 0u);
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(rows))
  for (std::int64_t i = 0; i < rows; ++i) {
    const uint c = listed(std::size_t(i));
    uint pairs = 0;
    for (uint k = 0; k < c; ++k) {
      const uint j = in.list[std::size_t{k} * n + std::size_t(i)];
      if (j <= uint(i)) continue;
      const uint cj = listed(j);
      for (uint m = 0; m < cj; ++m) {
        if (in.list[std::size_t{m} * n + j] == uint(i)) {
          mirror[at[i] + k] = m;
          ++pairs;
          break;
        }
      }
    }
    owned[std::size_t(i) + 1] = pairs;
  }
  for (std::size_t i = 0; i < n; ++i) owned[i + 1] += owned[i];
  contact_pair_list_.resize(owned[n]);
  // The pairs, owner by owner; each partner slot taken by its one owner.
  std::vector<std::uint8_t> taken(first[n], 0u);
  ContactPair* pairs = contact_pair_list_.data();
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(rows))
  for (std::int64_t i = 0; i < rows; ++i) {
    const uint c = listed(std::size_t(i));
    uint next = owned[std::size_t(i)];
    for (uint k = 0; k < c; ++k) {
      const uint m = mirror[at[i] + k];
      if (m == kNoPair) continue;
      const uint j = in.list[std::size_t{k} * n + std::size_t(i)];
      pairs[next++] = {uint(i), j, at[i] + k, at[j] + m};
      taken[at[i] + k] = 1u;
      taken[at[j] + m] = 1u;
    }
  }
  // The slots no pair covers (a partner that is static, over capacity or does not list i): each
  // evaluated by its particle.
  std::vector<uint> own(n + 1, 0u);
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(rows))
  for (std::int64_t i = 0; i < rows; ++i) {
    uint s = 0;
    for (uint k = 0; k < listed(std::size_t(i)); ++k) s += taken[at[i] + k] == 0u ? 1u : 0u;
    own[std::size_t(i) + 1] = s;
  }
  for (std::size_t i = 0; i < n; ++i) own[i + 1] += own[i];
  contact_own_slots_.resize(own[n]);
  ContactSlot* slots = contact_own_slots_.data();
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel_heavy(rows))
  for (std::int64_t i = 0; i < rows; ++i) {
    uint next = own[std::size_t(i)];
    for (uint k = 0; k < listed(std::size_t(i)); ++k) {
      if (taken[at[i] + k] == 0u) slots[next++] = {uint(i), k};
    }
  }
  contact_slot_force_.resize(first[n]);
  contact_pairs_ready_ = true;
  return true;
}

}  // namespace motes::openmp
