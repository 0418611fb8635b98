// contacts_compute against the O(N^2) oracle, the kernel alone. The lists are the oracle's,
// built (with its grid) at positions X0; the particles have moved since, each by 0.4 skin in a
// random direction, as between two rebuilds. Written: ParticlePos/Vel (now), ParticleBody,
// ParticleMaterial, the lists (NeighbourList, NeighbourCount, NeighbourRefPos = X0), the grid of
// X0 (GridOrder, GridCellStart, SortedBody: the walk of particles with more neighbours than K),
// ContactLaws and Planes; every other buffer is poisoned; ParticleForce (by particle id, w = 0;
// with MOTES_FLAG_POSITION the shifts of position contacts, w their number) is read back. Each case
// runs twice: with K = 16, and with K = 2 so that most particles walk the grid instead; the two
// forces must be equal, value for value (the same pairs in the same order), and both close to the
// oracle's.
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

constexpr double kContactsComputeTolerance = 1.0e-7;

class ContactsCompute : public DeviceTest {
 protected:
  /// ParticleForce on the device for lists of capacity K (the world's sizes otherwise).
  std::vector<vec4> device_force(const World& w, const motes_ref::Grid& g,
                                 const motes_ref::Neighbours& nb, const motes_ref::Particles& now,
                                 uint capacity) {
    motes::Sizes sizes = w.sizes;
    sizes.neighbour_capacity = capacity;
    StepParams params = w.params;
    params.neighbour_capacity = capacity;
    std::vector<vec4> got;
    allocate(sizes);
    if (HasFatalFailure()) return got;
    poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::ParticleBody,
                    Buffer::ParticleMaterial, Buffer::NeighbourList, Buffer::NeighbourCount,
                    Buffer::NeighbourRefPos, Buffer::GridOrder, Buffer::GridCellStart,
                    Buffer::SortedBody, Buffer::ContactLaws, Buffer::Planes,
                    Buffer::LinkExclusions});
    write(Buffer::LinkExclusions, w.link_exclusions);
    write(Buffer::ParticlePos, now.pos);
    write(Buffer::ParticleVel, now.vel);
    write(Buffer::ParticleBody, now.body);
    write(Buffer::ParticleMaterial, now.material);
    write(Buffer::NeighbourList, list_buffer(nb, capacity));
    write(Buffer::NeighbourCount, nb.count);
    write(Buffer::NeighbourRefPos, nb.ref);
    write(Buffer::GridOrder, g.order);
    write(Buffer::GridCellStart, g.cell_start);
    write(Buffer::SortedBody, g.sorted_body);
    write(Buffer::ContactLaws, w.laws);
    write(Buffer::Planes, w.planes);
    if (HasFatalFailure()) return got;
    run(motes::Kernel::ContactsCompute, params);
    if (HasFatalFailure()) return got;
    read(Buffer::ParticleForce, got);
    return got;
  }

  void run_case(const std::string& layout, const World& w) {
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, w.params);
    const motes_ref::Neighbours nb = motes_ref::neighbours_build(w.particles, g, w.params);
    // The particles now: each dynamic one moved 0.4 skin since the lists were built.
    motes_ref::Particles now = w.particles;
    Rng rng(static_cast<std::uint32_t>(w.particles.size()) + 5u);
    const std::vector<vec4> moved = moved_by(rng, w.particles.pos, w.params.neighbour_skin, 0.4f);
    for (std::size_t i = 0; i < now.size(); ++i) {
      if (now.vel[i].w != 0.0f) now.pos[i] = moved[i];
    }
    const std::vector<vec4> want =
        motes_ref::contacts_compute(now, w.laws, w.planes, w.params, nb.count);
    const std::size_t n = w.particles.size();
    // The layout must really make contacts, or the case proves little.
    std::size_t pushed = 0;
    for (const vec4& f : want) pushed += (f.x != 0.0f || f.y != 0.0f || f.z != 0.0f) ? 1 : 0;
    if (n >= 31) {
      ASSERT_GE(pushed, n / 4) << "too few particles touch anything";
    }
    std::size_t walking = 0;
    for (uint c : nb.count) walking += c > 2 ? 1 : 0;

    const std::vector<vec4> listed = device_force(w, g, nb, now, w.params.neighbour_capacity);
    ASSERT_FALSE(HasFatalFailure());
    const std::vector<vec4> walked = device_force(w, g, nb, now, 2);
    ASSERT_FALSE(HasFatalFailure());

    // Static particles: exactly zero, whatever the sign of zero.
    std::vector<uint> static_nonzero;
    for (std::size_t i = 0; i < n; ++i) {
      if (w.particles.vel[i].w != 0.0f) continue;
      const vec4 f = listed[i];
      static_nonzero.push_back(f.x != 0.0f || f.y != 0.0f || f.z != 0.0f || f.w != 0.0f ? 1 : 0);
    }
    // The lists and the walk: the same value (-0 and +0 alike) in every component.
    std::size_t differ = 0;
    for (std::size_t i = 0; i < std::min(listed.size(), walked.size()); ++i) {
      const vec4 a = listed[i], b = walked[i];
      differ += a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w ? 0 : 1;
    }
    begin_case("contacts_compute/" + layout, n);
    check_close("ParticleForce", listed, want, kContactsComputeTolerance);
    check_close("ParticleForce (K = 2: walks)", walked, want, kContactsComputeTolerance);
    check_that("K = 2 and K = 16 give the same forces",
               differ == 0 && listed.size() == walked.size());
    check_that("some particles walk the grid at K = 2", n < 31 || walking > 0);
    check_identical("ParticleForce of static particles is 0", static_nonzero,
                    std::vector<uint>(static_nonzero.size(), 0u));
    end_case();
  }
};

TEST_P(ContactsCompute, Empty) { run_case("random", random_world(21, 0, 0, kTestSkin)); }
TEST_P(ContactsCompute, One) { run_case("random", random_world(22, 1, 0, kTestSkin)); }
TEST_P(ContactsCompute, Random31) { run_case("random", random_world(23, 31, 0, kTestSkin)); }
TEST_P(ContactsCompute, Random1234) { run_case("random", random_world(24, 1234, 0, kTestSkin)); }
TEST_P(ContactsCompute, Random1234Clamped) {
  run_case("random_clamped", random_world(24, 1234, MOTES_FLAG_CLAMP_ATTRACTION, kTestSkin));
}
TEST_P(ContactsCompute, Linked1234) {
  // Cloth and rope particles: no force between particles of one object within two lattice steps.
  run_case("linked", with_linked(random_world(25, 1234, 0, kTestSkin), 25));
}
TEST_P(ContactsCompute, MeshLinked1234) {
  // Cloths from meshes: no force between the pairs their LinkExclusions lists hold.
  run_case("mesh_linked", with_mesh_linked(random_world(29, 1234, 0, kTestSkin), 29));
}
TEST_P(ContactsCompute, Positions1234) {
  // Position contacts: each particle's shifts and their number (shared/particle_shift.h).
  run_case("positions",
           random_world(26, 1234, MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE, kTestSkin));
}
TEST_P(ContactsCompute, LinkedPositions1234) {
  run_case(
      "linked_positions",
      with_linked(random_world(27, 1234, MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE, kTestSkin), 27));
}
TEST_P(ContactsCompute, Random20000) {
  run_case("random_clamped", random_world(25, 20000, MOTES_FLAG_CLAMP_ATTRACTION, kTestSkin));
}

TEST_P(ContactsCompute, OnCellFacesExactCell) {
  // Exact face coordinates (cell 0.5 + 0.125 m): many pairs at exactly the cutoff, or coincident,
  // when the lists are built; then everything moves.
  Rng rng(26);
  run_case("on_cell_faces_exact", make_world(rng, on_cell_faces(rng, 1234, 0.25f, 0.125f),
                                             MOTES_FLAG_CLAMP_ATTRACTION, true, 0.125f));
}

TEST_P(ContactsCompute, OnCellFacesInexactCell) {
  Rng rng(27);
  run_case("on_cell_faces_inexact",
           make_world(rng, on_cell_faces(rng, 1234, 0.005f, kTestSkin), 0, true, kTestSkin));
}

TEST_P(ContactsCompute, AllInOneCell) {
  // 300 particles in one cell: many terms per particle, most lists beyond K.
  Rng rng(28);
  run_case("one_cell",
           make_world(rng, one_cell(rng, 300, 0.005f, vec3(0.07f, -0.03f, 0.11f), kTestSkin), 0,
                      true, kTestSkin));
}

TEST_P(ContactsCompute, FarFromOrigin) {
  Rng rng(29);
  const float rmax = 0.05f;
  auto pos = random_cloud(rng, 1234, rmax, dense_side(1234, rmax), vec3(1e5f, -1e5f, 1e5f));
  // A skin of 0.1 m: positions here round to 8 mm, and the moves must stay inside half a skin.
  run_case("far_1e5", make_world(rng, std::move(pos), MOTES_FLAG_CLAMP_ATTRACTION, false, 0.1f));
}

TEST_P(ContactsCompute, SmallTable) {
  // T = 64 for 1234 particles: rows share buckets all the time, so a bucket visited twice (or
  // skipped) by the walk changes the force.
  World w = random_world(30, 1234, 0, kTestSkin);
  w.sizes.table = 64;
  w.params.table_mask = 63;
  run_case("table_64", w);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ContactsCompute, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
