// contacts_compute against the O(N^2) oracle, the kernel alone: the particles (ParticlePos/Vel/
// Body/Material), the oracle's grid (GridOrder, GridCellStart, Sorted*) and the ContactLaws and
// Planes are written to the device, every other buffer is poisoned, and ParticleForce (indexed by
// particle id, w = 0) is read back.
//
// Tolerance: NMSE 1e-7 (the default). Each term comes from the same shared function and the same
// floats; the device sums the terms in float in the canonical order, the oracle in double in id
// order, so the expected error is a few float roundings per particle: NMSE ~ K u^2 with K terms
// and u = 2^-24, about 1e-14 (openmp measures 1e-15 to 5e-14). A GPU may also fuse multiply-adds
// inside each term; near-zero overlaps (rsum - dist) amplify that relative error, and a pair at
// distance rsum within an ulp may count on one device and not on another, with a dashpot force
// that does not vanish at zero overlap: 1e-7 leaves room for that. It still fails on a single
// missed contact: dropping one term from the oracle measures 2e-5 to 5e-4 at N = 1234, 6e-6 at
// 20,000 and 8e-7 far from the origin (only one_cell, with ~300 terms per particle, hides it:
// 4e-8), and on 1 in 1000 terms dropped in every layout (4e-5 to 2e-3).
// Static particles must get exactly 0 (checked separately).
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

constexpr double kTolerance = 1.0e-7;

class ContactsCompute : public DeviceTest {
 protected:
  void run_case(const std::string& layout, const World& w) {
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, w.params);
    const std::vector<vec4> want =
        motes_ref::contacts_compute(w.particles, w.laws, w.planes, w.params);
    const std::size_t n = w.particles.size();
    // The layout must really make contacts, or the case proves little.
    std::size_t pushed = 0;
    for (const vec4& f : want) pushed += (f.x != 0.0f || f.y != 0.0f || f.z != 0.0f) ? 1 : 0;
    if (n >= 31) {
      ASSERT_GE(pushed, n / 4) << "too few particles touch anything";
    }

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but(
        {Buffer::ParticlePos, Buffer::ParticleVel, Buffer::ParticleBody, Buffer::ParticleMaterial,
         Buffer::GridOrder, Buffer::GridCellStart, Buffer::SortedPos, Buffer::SortedVel,
         Buffer::SortedBody, Buffer::SortedMaterial, Buffer::ContactLaws, Buffer::Planes}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleMaterial, w.particles.material));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridOrder, g.order));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridCellStart, g.cell_start));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedPos, g.sorted_pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedVel, g.sorted_vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedBody, g.sorted_body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedMaterial, g.sorted_material));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ContactLaws, w.laws));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::Planes, w.planes));
    device().contacts_compute(w.params);
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleForce, got));

    // Static particles: exactly zero, whatever the sign of zero.
    std::vector<uint> static_nonzero;
    for (std::size_t i = 0; i < n; ++i) {
      if (w.particles.vel[i].w != 0.0f) continue;
      const vec4 f = got[i];
      static_nonzero.push_back(f.x != 0.0f || f.y != 0.0f || f.z != 0.0f || f.w != 0.0f ? 1 : 0);
    }
    begin_case("contacts_compute/" + layout, n);
    check_close("ParticleForce", got, want, kTolerance);
    check_identical("ParticleForce of static particles is 0", static_nonzero,
                    std::vector<uint>(static_nonzero.size(), 0u));
    end_case();
  }
};

TEST_P(ContactsCompute, Empty) { run_case("random", random_world(21, 0)); }
TEST_P(ContactsCompute, One) { run_case("random", random_world(22, 1)); }
TEST_P(ContactsCompute, Random31) { run_case("random", random_world(23, 31)); }
TEST_P(ContactsCompute, Random1234) { run_case("random", random_world(24, 1234)); }
TEST_P(ContactsCompute, Random1234Clamped) {
  run_case("random_clamped", random_world(24, 1234, MOTES_FLAG_CLAMP_ATTRACTION));
}
TEST_P(ContactsCompute, Random20000) {
  run_case("random_clamped", random_world(25, 20000, MOTES_FLAG_CLAMP_ATTRACTION));
}

TEST_P(ContactsCompute, OnCellFacesExactCell) {
  // Exact face coordinates: many pairs at exactly rsum (no contact) or coincident (no force).
  Rng rng(26);
  run_case("on_cell_faces_exact",
           make_world(rng, on_cell_faces(rng, 1234, 0.25f), MOTES_FLAG_CLAMP_ATTRACTION, true));
}

TEST_P(ContactsCompute, OnCellFacesInexactCell) {
  Rng rng(27);
  run_case("on_cell_faces_inexact", make_world(rng, on_cell_faces(rng, 1234, 0.005f), 0, true));
}

TEST_P(ContactsCompute, AllInOneCell) {
  // Every pair of different bodies overlaps: ~300 terms per particle.
  Rng rng(28);
  run_case("one_cell",
           make_world(rng, one_cell(rng, 300, 0.005f, vec3(0.07f, -0.03f, 0.11f)), 0, true));
}

TEST_P(ContactsCompute, FarFromOrigin) {
  Rng rng(29);
  const float rmax = 0.05f;
  auto pos = random_cloud(rng, 1234, rmax, dense_side(1234, rmax), vec3(1e5f, -1e5f, 1e5f));
  run_case("far_1e5", make_world(rng, std::move(pos), MOTES_FLAG_CLAMP_ATTRACTION, false));
}

TEST_P(ContactsCompute, SmallTable) {
  // T = 64 for 1234 particles: rows share buckets all the time, so a bucket visited twice (or
  // skipped) by the 27-cell walk changes the force.
  World w = random_world(30, 1234);
  w.sizes.table = 64;
  w.params.table_mask = 63;
  run_case("table_64", w);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ContactsCompute, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
