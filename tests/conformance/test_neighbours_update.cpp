// neighbours_update against the oracle (motes_ref::neighbours_update): every output must be
// IDENTICAL. The particles (ParticlePos/Vel/Body/Material) and NeighbourState are written, every
// other buffer is poisoned, and the family runs twice. With the rebuild word 0 nothing may be
// written (every grid and list buffer comes back poisoned, NeighbourState as written); with it
// set, the first call rebuilds and the second must do nothing more: the grid and the lists must
// equal the oracle's (as in test_grid_build.cpp and test_neighbours_build.cpp), NeighbourState
// with rebuild 0 and builds + 1.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "conformance.h"
#include "list_support.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

class NeighboursUpdate : public ListTest {
 protected:
  void run_case(const std::string& layout, const World& w, bool rebuild) {
    const std::vector<uint> state_in = {rebuild ? 1u : 0u, kBuildsBefore, 77u, 88u};
    motes_ref::Grid g;
    motes_ref::Neighbours want;
    ASSERT_EQ(motes_ref::neighbours_update(w.particles, state_in, w.params, g, want), rebuild)
        << "the case's own premise";
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::ParticleBody,
                        Buffer::ParticleMaterial, Buffer::NeighbourState}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleMaterial, w.particles.material));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state_in));
    // Twice: the first call rebuilds (when asked), the second must then do nothing more.
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::NeighboursUpdate, w.params));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::NeighboursUpdate, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());

    motes_ref::Grid got;
    std::vector<uint> list, count, state;
    std::vector<vec4> ref;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::GridOrder, got.order));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::GridCellStart, got.cell_start));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::SortedPos, got.sorted_pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourList, list));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourCount, count));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));

    const std::size_t n = w.particles.size();
    begin_case(std::string("neighbours_update/") + layout + (rebuild ? " rebuild" : " no rebuild"),
               n);
    if (rebuild) {
      check_identical("GridOrder", got.order, g.order);
      check_identical("GridCellStart", got.cell_start, g.cell_start);
      check_identical("SortedPos", got.sorted_pos, g.sorted_pos);
      check_lists(list, count, ref, state, want, w.params.neighbour_capacity);
    } else {
      // Untouched: still the poison (0xFF bytes) of every output.
      check_identical("GridOrder untouched", got.order, std::vector<uint>(n, 0xFFFFFFFFu));
      check_identical("NeighbourCount untouched", count, std::vector<uint>(n, 0xFFFFFFFFu));
      check_identical("NeighbourList untouched", list, std::vector<uint>(list.size(), 0xFFFFFFFFu));
      check_identical("NeighbourState untouched", state, state_in);
    }
    end_case();
  }
};

TEST_P(NeighboursUpdate, NoRebuild) {
  run_case("random", random_world(221, 1234, 0, kTestSkin), false);
}
TEST_P(NeighboursUpdate, Rebuild) {
  run_case("random", random_world(221, 1234, 0, kTestSkin), true);
}
TEST_P(NeighboursUpdate, Rebuild20000) {
  // Large enough for a two-level bucket scan on Vulkan; the oracle's lists are O(N^2).
  run_case("random", random_world(222, 20000, 0, kTestSkin), true);
}

INSTANTIATE_TEST_SUITE_P(Conformance, NeighboursUpdate, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
