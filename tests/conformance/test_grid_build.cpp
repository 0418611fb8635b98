// grid_build against the oracle (tests/reference): every output must be IDENTICAL.
//
// Tolerance: none. The bucket is integer arithmetic on grid_cell_coord = floor(x * inv_cell_size),
// one correctly rounded float multiply, which every IEEE device computes alike (no contraction is
// possible); the order is the unique stable sort by bucket; the bucket starts follow from it; the
// Sorted* buffers are copies, compared bitwise. Inputs: ParticlePos/Vel/Body/Material; every other
// buffer is poisoned, so an output left unwritten (e.g. the start of an empty bucket) fails.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

class GridBuild : public DeviceTest {
 protected:
  void run_case(const std::string& layout, const World& w) {
    const motes_ref::Grid want = motes_ref::grid_build(w.particles, w.params);
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel,
                                            Buffer::ParticleBody, Buffer::ParticleMaterial}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleMaterial, w.particles.material));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::GridBuild, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());

    motes_ref::Grid got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::GridBucket, got.bucket));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::GridOrder, got.order));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::GridCellStart, got.cell_start));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::SortedPos, got.sorted_pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::SortedBody, got.sorted_body));

    begin_case("grid_build/" + layout, w.sizes.particles);
    check_identical("GridBucket", got.bucket, want.bucket);
    check_identical("GridOrder", got.order, want.order);
    check_identical("GridCellStart", got.cell_start, want.cell_start);
    check_identical("SortedPos", got.sorted_pos, want.sorted_pos);
    check_identical("SortedBody", got.sorted_body, want.sorted_body);
    end_case();
  }

  /// Number of distinct buckets the oracle uses (to check a layout is what its name says).
  static std::size_t buckets_used(const World& w) {
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, w.params);
    std::size_t used = 0;
    for (std::size_t b = 0; b + 1 < g.cell_start.size(); ++b) {
      used += g.cell_start[b + 1] > g.cell_start[b] ? 1 : 0;
    }
    return used;
  }
};

TEST_P(GridBuild, Empty) { run_case("random", random_world(1, 0)); }
TEST_P(GridBuild, One) { run_case("random", random_world(2, 1)); }
TEST_P(GridBuild, Random31) { run_case("random", random_world(3, 31)); }
TEST_P(GridBuild, Random1234) { run_case("random", random_world(4, 1234)); }
TEST_P(GridBuild, Random65536) { run_case("random", random_world(5, 65536)); }
// T = 2^21 buckets: the Vulkan bucket-count scan needs three levels (2,097,153 -> 2,049 -> 3).
TEST_P(GridBuild, Random300000) { run_case("random", random_world(13, 300000)); }

TEST_P(GridBuild, OnCellFacesExactCell) {
  // cell = 0.5 m: every face coordinate k * 0.5 is exact, so floor() sits right on the boundary.
  Rng rng(6);
  run_case("on_cell_faces_exact", make_world(rng, on_cell_faces(rng, 1234, 0.25f), 0, true));
}

TEST_P(GridBuild, OnCellFacesInexactCell) {
  // cell = 0.01 m: k * cell rounds either way of the true face; floor(x * inv_cell) decides.
  Rng rng(7);
  run_case("on_cell_faces_inexact", make_world(rng, on_cell_faces(rng, 1234, 0.005f), 0, true));
}

TEST_P(GridBuild, AllInOneCell) {
  Rng rng(8);
  const World w = make_world(rng, one_cell(rng, 300, 0.005f, vec3(0.07f, -0.03f, 0.11f)), 0, true);
  ASSERT_EQ(buckets_used(w), 1u);
  run_case("one_cell", w);
}

TEST_P(GridBuild, FarFromOrigin) {
  // 1e5 m from the origin, floats are 8 mm apart: 5 cm particles keep distinct positions.
  Rng rng(9);
  const float rmax = 0.05f;
  auto pos = random_cloud(rng, 1234, rmax, dense_side(1234, rmax), vec3(1e5f, -1e5f, 1e5f));
  run_case("far_1e5", make_world(rng, std::move(pos), 0, false));
}

TEST_P(GridBuild, HugeCoordinates) {
  // Cell indices beyond 2^30 clamp; x * inv_cell overflowing to infinity clamps too.
  Rng rng(10);
  run_case("huge_coordinates", make_world(rng, with_huge_coordinates(rng, 1234, 0.005f), 0, false));
}

TEST_P(GridBuild, SmallTable) {
  // T = 64 for 1234 particles: about 20 particles per bucket, many rows sharing buckets.
  World w = random_world(11, 1234);
  w.sizes.table = 64;
  w.params.table_mask = 63;
  run_case("table_64", w);
}

INSTANTIATE_TEST_SUITE_P(Conformance, GridBuild, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
