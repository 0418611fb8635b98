// Which particle pairs never touch (shared/links.h: contact_excluded, contact_listed,
// contact_skipped), checked against the rule written out by hand: the same body, one cloth or
// rope's particles within two lattice steps, or a mesh cloth's pairs in the LinkExclusions lists.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <vector>

#include "shared/links.h"

namespace {

using motes::shared::contact_excluded;
using motes::shared::contact_listed;
using motes::shared::contact_skipped;
using motes::shared::linked_body;
using motes::shared::linked_mesh_body;

TEST(LinkExclusion, RigidBodiesAndFreeSpheres) {
  EXPECT_TRUE(contact_excluded(7u, 7u));
  EXPECT_FALSE(contact_excluded(7u, 8u));
  EXPECT_FALSE(contact_excluded(0u, 0x7fffffffu));
  // A rigid body id never matches a cloth particle, whatever its bits.
  EXPECT_FALSE(contact_excluded(linked_body(0u, 0u, 0u) & 0x7fffffffu, linked_body(0u, 0u, 0u)));
}

TEST(LinkExclusion, EveryLatticeOffset) {
  for (std::uint32_t object : {0u, 1u, MOTES_LINKED_MAX_OBJECTS - 1u}) {
    for (int du = -4; du <= 4; ++du) {
      for (int dv = -4; dv <= 4; ++dv) {
        const std::uint32_t u = 500u, v = 3u;
        const std::uint32_t a = linked_body(object, u, v);
        const std::uint32_t b = linked_body(object, static_cast<std::uint32_t>(500 + du),
                                            static_cast<std::uint32_t>(3 + dv));
        const bool near = std::abs(du) <= 2 && std::abs(dv) <= 2;
        EXPECT_EQ(contact_excluded(a, b), near) << object << " " << du << " " << dv;
        EXPECT_EQ(contact_excluded(b, a), near) << object << " " << du << " " << dv;
        // Another object at the same places always touches.
        const std::uint32_t other =
            linked_body((object + 1u) % MOTES_LINKED_MAX_OBJECTS,
                        static_cast<std::uint32_t>(500 + du), static_cast<std::uint32_t>(3 + dv));
        EXPECT_FALSE(contact_excluded(a, other));
      }
    }
  }
}

TEST(LinkExclusion, LatticeEdges) {
  EXPECT_TRUE(contact_excluded(linked_body(5u, 0u, 0u), linked_body(5u, 2u, 2u)));
  EXPECT_FALSE(contact_excluded(linked_body(5u, 0u, 0u), linked_body(5u, 1023u, 0u)));
  EXPECT_TRUE(contact_excluded(linked_body(5u, 1023u, 1021u), linked_body(5u, 1021u, 1023u)));
  EXPECT_FALSE(contact_excluded(linked_body(5u, 1023u, 1020u), linked_body(5u, 1023u, 1023u)));
}

TEST(LinkExclusion, MeshClothWordsAreDecidedByTheLists) {
  const std::uint32_t last = MOTES_LINKED_MAX_OBJECTS - 1u;
  for (std::uint32_t object : {0u, 3u, last}) {
    const std::uint32_t a = linked_mesh_body(object, 0u);
    const std::uint32_t b = linked_mesh_body(object, 1u);
    // Never decided by the lattice rule, however near the vertex numbers are...
    EXPECT_FALSE(contact_excluded(a, b));
    EXPECT_TRUE(contact_excluded(a, a));
    // ...but looked up for two particles of one mesh cloth, and only for them.
    EXPECT_TRUE(contact_listed(a, b));
    EXPECT_TRUE(contact_listed(b, a));
    EXPECT_FALSE(contact_listed(a, linked_mesh_body((object + 1u) % MOTES_LINKED_MAX_OBJECTS, 1u)));
    EXPECT_FALSE(contact_listed(a, linked_body(object, 0u, 1u)));
    EXPECT_FALSE(contact_listed(linked_body(object, 0u, 1u), a));
    EXPECT_FALSE(contact_excluded(a, linked_body(object, 0u, 0u)));
    EXPECT_FALSE(contact_listed(a, object));  // a rigid body's id
  }
  // The largest vertex and object fit without touching the flag bits.
  const std::uint32_t top = linked_mesh_body(last, MOTES_LINKED_MAX_MESH_POINTS - 1u);
  EXPECT_EQ(top, 0xffffffffu);
  EXPECT_FALSE(contact_listed(linked_body(last, 1023u, 1023u), top));
}

TEST(LinkExclusion, ListLookup) {
  // Particles [10, 16) are linked (Nl = 10, N = 16): 10 and 11 a rope, 12..15 one mesh cloth
  // (object 1) where 12 excludes 13 and 15, 13 excludes 12, 14 none, 15 excludes 12.
  const std::uint32_t n = 16, nl = 10;
  const std::vector<std::uint32_t> ex = {0,  0,  0,  2, 3, 3, 4,  // starts of 10..15, then the end
                                         13, 15, 12, 12};
  const auto mesh = [](std::uint32_t k) { return linked_mesh_body(1u, k - 12u); };
  const auto skipped = [&](std::uint32_t i, std::uint32_t j) {
    return contact_skipped(mesh(i), mesh(j), i, j, ex.data(), n, nl);
  };
  EXPECT_TRUE(skipped(12, 13));
  EXPECT_FALSE(skipped(12, 14));
  EXPECT_TRUE(skipped(12, 15));
  EXPECT_TRUE(skipped(13, 12));
  EXPECT_FALSE(skipped(13, 14));
  EXPECT_FALSE(skipped(13, 15));
  EXPECT_FALSE(skipped(14, 12));
  EXPECT_FALSE(skipped(14, 15));
  EXPECT_TRUE(skipped(15, 12));
  EXPECT_FALSE(skipped(15, 14));
  EXPECT_TRUE(skipped(14, 14));  // the same particle
  // Other pairs never read the lists (a null pointer would crash if they did).
  EXPECT_FALSE(contact_skipped(linked_body(0u, 0u, 0u), mesh(12), 10, 12, nullptr, n, nl));
  EXPECT_TRUE(
      contact_skipped(linked_body(0u, 0u, 0u), linked_body(0u, 1u, 0u), 10, 11, nullptr, n, nl));
  EXPECT_FALSE(contact_skipped(3u, mesh(12), 3, 12, nullptr, n, nl));
}

}  // namespace
