// neighbours_build against the oracle: every output must be IDENTICAL.
//
// The particles (ParticlePos/Vel/Body), the oracle's grid (GridOrder, GridCellStart, SortedPos,
// SortedBody) and a NeighbourState are written, every other buffer is poisoned. Read back:
// NeighbourCount (every particle's full count), the first min(count, K) entries of each list (entry
// k of particle i at k * N + i; the rest is unspecified), NeighbourRefPos (= ParticlePos, bitwise)
// and NeighbourState (rebuild 0, builds + 1, particles over capacity, largest count).
//
// Tolerance: none. Which pairs are listed is decided by shared::neighbour_within, whose products
// are rounded on their own on every backend (mul_rn), so that no fused multiply-add can move a
// pair across the cutoff; the order is the canonical walk, which the oracle writes differently (as
// the first occurrence of each bucket among the 27 cells, then grid order), by brute force.
//
// With impulse contacts (NeighboursBuildStamps), the lists of the last build are written too, most
// of them equal to the new ones and some changed (an entry replaced, two swapped, one dropped),
// with ImpulseStamp at the last build's count for most rigid particles: the stamps read back must
// equal the oracle's (motes_ref::impulse_stamps_after_build: moved on where the list is unchanged),
// bitwise.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "conformance.h"
#include "list_support.h"
#include "reference/reference.h"
#include "shared/neighbours.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

class NeighboursBuild : public ListTest {
 protected:
  void run_case(const std::string& layout, const World& w) {
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, w.params);
    const motes_ref::Neighbours want = motes_ref::neighbours_build(w.particles, g, w.params);
    const std::size_t n = w.particles.size();
    std::size_t listed = 0;
    for (uint c : want.count) listed += c;
    if (n >= 31) {
      ASSERT_GE(listed, n / 2) << "too few neighbours for the case to prove much";
    }

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::ParticleBody,
                        Buffer::GridOrder, Buffer::GridCellStart, Buffer::SortedPos,
                        Buffer::SortedBody, Buffer::NeighbourState, Buffer::LinkExclusions}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::LinkExclusions, w.link_exclusions));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridOrder, g.order));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridCellStart, g.cell_start));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedPos, g.sorted_pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedBody, g.sorted_body));
    ASSERT_NO_FATAL_FAILURE(
        write(Buffer::NeighbourState, std::vector<uint>{1u, kBuildsBefore, 77u, 88u}));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::NeighboursBuild, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());

    std::vector<uint> list, count, state;
    std::vector<vec4> ref;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourList, list));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourCount, count));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));

    begin_case("neighbours_build/" + layout, n);
    check_lists(list, count, ref, state, want, w.params.neighbour_capacity);
    end_case();
  }
};

class NeighboursBuildStamps : public ListTest {
 protected:
  void run_case(const std::string& layout, World w) {
    w.sizes.impulse = 1;
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, w.params);
    const motes_ref::Neighbours want = motes_ref::neighbours_build(w.particles, g, w.params);
    const std::size_t n = w.particles.size();
    const std::size_t nr = w.particles.rigid;
    const uint capacity = w.params.neighbour_capacity;
    // The last build's lists: the new ones, some changed.
    Rng rng(static_cast<std::uint32_t>(n) + 91u);
    std::vector<uint> old_list = list_buffer(want, capacity);
    std::vector<uint> old_count = want.count;
    std::size_t changed = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const uint c = std::min(old_count[i], capacity);
      if (c == 0 || !rng.chance(0.3f)) continue;
      ++changed;
      const float how = rng.unit();
      if (how < 0.4f) {
        old_list[std::size_t{rng.below(c)} * n + i] = rng.below(static_cast<uint>(n));
      } else if (how < 0.7f && c >= 2) {
        std::swap(old_list[0 * n + i], old_list[std::size_t{c - 1} * n + i]);
      } else {
        old_count[i] -= 1;
      }
    }
    const uint built = kBuildsBefore;
    std::vector<uint> stamp(nr);
    for (uint& s : stamp) s = rng.chance(0.8f) ? built : built - 1u;
    std::vector<uint> want_stamp = stamp;
    motes_ref::impulse_stamps_after_build(w.particles, old_list, old_count, want, w.params, built,
                                          want_stamp);
    std::size_t moved = 0;
    for (std::size_t i = 0; i < nr; ++i) moved += want_stamp[i] != stamp[i] ? 1 : 0;

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::ParticleBody,
                        Buffer::GridOrder, Buffer::GridCellStart, Buffer::SortedPos,
                        Buffer::SortedBody, Buffer::NeighbourState, Buffer::LinkExclusions,
                        Buffer::NeighbourList, Buffer::NeighbourCount, Buffer::ImpulseStamp}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::LinkExclusions, w.link_exclusions));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridOrder, g.order));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridCellStart, g.cell_start));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedPos, g.sorted_pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedBody, g.sorted_body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourList, old_list));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourCount, old_count));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ImpulseStamp, stamp));
    ASSERT_NO_FATAL_FAILURE(
        write(Buffer::NeighbourState, std::vector<uint>{1u, kBuildsBefore, 77u, 88u}));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::NeighboursBuild, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());

    std::vector<uint> list, count, state, got_stamp;
    std::vector<vec4> ref;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourList, list));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourCount, count));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ImpulseStamp, got_stamp));

    begin_case("neighbours_build/" + layout, n);
    check_lists(list, count, ref, state, want, capacity);
    check_identical("ImpulseStamp", got_stamp, want_stamp);
    check_that("some lists changed and some stamps moved on",
               n < 31 || (changed > 0 && moved > 0 && moved < nr));
    end_case();
  }
};

World with_capacity(World w, uint capacity) {
  w.sizes.neighbour_capacity = capacity;
  w.params.neighbour_capacity = capacity;
  return w;
}

TEST_P(NeighboursBuild, Empty) { run_case("random", random_world(201, 0, 0, kTestSkin)); }
TEST_P(NeighboursBuild, One) { run_case("random", random_world(202, 1, 0, kTestSkin)); }
TEST_P(NeighboursBuild, Random31) { run_case("random", random_world(203, 31, 0, kTestSkin)); }
TEST_P(NeighboursBuild, Random1234) { run_case("random", random_world(204, 1234, 0, kTestSkin)); }
TEST_P(NeighboursBuild, Random20000) { run_case("random", random_world(205, 20000, 0, kTestSkin)); }
TEST_P(NeighboursBuild, NoSkin) { run_case("skin_0", random_world(206, 1234, 0, 0.0f)); }
TEST_P(NeighboursBuild, CapacityOne) {
  // Most particles have more neighbours than they keep: their counts go on, their lists stop.
  run_case("capacity_1", with_capacity(random_world(207, 1234, 0, kTestSkin), 1));
}

TEST_P(NeighboursBuild, OnCellFacesExactCell) {
  // cell = 0.5 + 0.125 m: every face coordinate is exact, and many pairs sit exactly at the
  // cutoff 2 rmax + skin (not listed: the test is strict) or coincide.
  Rng rng(208);
  run_case("on_cell_faces_exact",
           make_world(rng, on_cell_faces(rng, 1234, 0.25f, 0.125f), 0, true, 0.125f));
}

TEST_P(NeighboursBuild, AllInOneCell) {
  // 300 particles in one cell: most counts far beyond K = 16, so most lists stop early.
  Rng rng(209);
  run_case("one_cell",
           make_world(rng, one_cell(rng, 300, 0.005f, vec3(0.07f, -0.03f, 0.11f), 0.001f), 0, true,
                      0.001f));
}

TEST_P(NeighboursBuild, FarFromOrigin) {
  Rng rng(210);
  const float rmax = 0.05f;
  auto pos = random_cloud(rng, 1234, rmax, dense_side(1234, rmax), vec3(1e5f, -1e5f, 1e5f));
  run_case("far_1e5", make_world(rng, std::move(pos), 0, false, 0.1f));
}

TEST_P(NeighboursBuild, SmallTable) {
  // T = 64 for 1234 particles: rows share buckets all the time, so a bucket visited twice (or
  // skipped) by the walk changes the list.
  World w = random_world(211, 1234, 0, kTestSkin);
  w.sizes.table = 64;
  w.params.table_mask = 63;
  run_case("table_64", w);
}

TEST_P(NeighboursBuild, Linked1234) {
  // Cloth and rope particles: pairs of one object within two lattice steps are not listed.
  run_case("linked", with_linked(random_world(212, 1234, 0, kTestSkin), 212));
}

TEST_P(NeighboursBuild, MeshLinked1234) {
  // Cloths from meshes: the pairs in their LinkExclusions lists are not listed.
  const World w = with_mesh_linked(random_world(213, 1234, 0, kTestSkin), 213);
  // The lists must remove pairs that would otherwise be listed, or the case proves little.
  motes_ref::Particles open = w.particles;
  open.never_touch.clear();
  const auto listed = [&](const motes_ref::Particles& p) {
    std::size_t total = 0;
    const motes_ref::Grid g = motes_ref::grid_build(p, w.params);
    for (uint c : motes_ref::neighbours_build(p, g, w.params).count) total += c;
    return total;
  };
  ASSERT_GE(listed(open), listed(w.particles) + 100);  // 148 pairs fewer here
  run_case("mesh_linked", w);
}

TEST_P(NeighboursBuild, Fluid1234) {
  // Fluid particles (docs/fluids.md, "Support radius and the neighbour lists"): the second half of
  // the free particles, whose pairs are listed closer than max(r_i + r_j, 4 r_fluid) + skin; the
  // cell edge grows to the largest such reach.
  World w = random_world(214, 1234, 0, kTestSkin);
  const uint nr = w.params.rigid_particle_count;
  const uint n = w.params.particle_count;
  w.params.fluid_first = nr + (n - nr) / 2;
  w.params.fluid_count = n - w.params.fluid_first;
  float reach = w.params.cell_size - w.params.neighbour_skin;
  for (uint i = w.params.fluid_first; i < n; ++i) {
    reach = std::max(reach, MOTES_FLUID_SUPPORT_RADII * w.particles.pos[i].w);
  }
  w.params.cell_size = reach + w.params.neighbour_skin;
  w.params.inv_cell_size = 1.0f / w.params.cell_size;
  // The fluid's reach must list pairs the contact reach does not, or the case proves little.
  const auto listed = [&](const motes::shared::StepParams& p) {
    std::size_t total = 0;
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, p);
    for (uint c : motes_ref::neighbours_build(w.particles, g, p).count) total += c;
    return total;
  };
  motes::shared::StepParams solid = w.params;
  solid.fluid_count = 0;
  ASSERT_GE(listed(w.params), listed(solid) + 200);
  run_case("fluid", w);
}

INSTANTIATE_TEST_SUITE_P(Conformance, NeighboursBuild, testing::ValuesIn(device_params()),
                         param_name);

TEST_P(NeighboursBuildStamps, Random1234) {
  run_case("impulse stamps", random_world(211, 1234, MOTES_FLAG_IMPULSE, kTestSkin));
}
TEST_P(NeighboursBuildStamps, CapacityTwo) {
  run_case("impulse stamps K = 2",
           with_capacity(random_world(212, 1234, MOTES_FLAG_IMPULSE, kTestSkin), 2));
}
INSTANTIATE_TEST_SUITE_P(Conformance, NeighboursBuildStamps, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
