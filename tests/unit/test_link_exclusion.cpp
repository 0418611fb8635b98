// Which particle pairs never touch (shared/links.h: contact_excluded), checked against the rule
// written out by hand: the same body, or one cloth or rope's particles within two lattice steps.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>

#include "shared/links.h"

namespace {

using motes::shared::contact_excluded;
using motes::shared::linked_body;

TEST(LinkExclusion, RigidBodiesAndFreeSpheres) {
  EXPECT_TRUE(contact_excluded(7u, 7u));
  EXPECT_FALSE(contact_excluded(7u, 8u));
  EXPECT_FALSE(contact_excluded(0u, 0x7fffffffu));
  // A rigid body id never matches a cloth particle, whatever its bits.
  EXPECT_FALSE(contact_excluded(linked_body(0u, 0u, 0u) & 0x7fffffffu, linked_body(0u, 0u, 0u)));
}

TEST(LinkExclusion, EveryLatticeOffset) {
  for (std::uint32_t object : {0u, 1u, 2047u}) {
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
            linked_body((object + 1u) % 2048u, static_cast<std::uint32_t>(500 + du),
                        static_cast<std::uint32_t>(3 + dv));
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

}  // namespace
