// What the neighbour-list cases share (test_neighbours_build.cpp, test_neighbours_update.cpp):
// the kept entries of a list buffer, NeighbourState after a build, and the list checks.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {

/// The first min(count, K) entries of every list, from a NeighbourList buffer (K * N).
inline std::vector<uint> kept_entries(const std::vector<uint>& list, const std::vector<uint>& count,
                                      uint capacity) {
  const std::size_t n = count.size();
  std::vector<uint> out;
  for (std::size_t i = 0; i < n; ++i) {
    for (uint k = 0; k < std::min(count[i], capacity); ++k) out.push_back(list[k * n + i]);
  }
  return out;
}

inline std::vector<uint> kept_entries(const motes_ref::Neighbours& want, uint capacity) {
  std::vector<uint> out;
  for (const std::vector<uint>& l : want.lists) {
    for (std::size_t k = 0; k < std::min<std::size_t>(l.size(), capacity); ++k) out.push_back(l[k]);
  }
  return out;
}

/// NeighbourState's builds word as the list cases write it.
constexpr uint kBuildsBefore = 41;

/// NeighbourState after a build from kBuildsBefore.
inline std::vector<uint> state_after(const motes_ref::Neighbours& want) {
  return {0u, kBuildsBefore + 1u, want.over_capacity, want.max_count};
}

/// The list checks shared by the list fixtures.
class ListTest : public DeviceTest {
 protected:
  /// EXPECTs the lists read back from the device equal to the oracle's.
  void check_lists(const std::vector<uint>& list, const std::vector<uint>& count,
                   const std::vector<vec4>& ref, const std::vector<uint>& state,
                   const motes_ref::Neighbours& want, uint capacity) {
    check_identical("NeighbourCount", count, want.count);
    if (count.size() == want.count.size()) {
      check_identical("NeighbourList (kept entries)", kept_entries(list, count, capacity),
                      kept_entries(want, capacity));
    }
    check_identical("NeighbourRefPos", ref, want.ref);
    check_identical("NeighbourState", state, state_after(want));
  }
};

}  // namespace motes_conf
