// energy_reduce against the oracle, the kernel alone: the bodies' and particles' state and
// EnergyPartials' header (the reference point) are written, every other buffer is poisoned (the
// blocks of EnergyPartials too: the kernel must write every one); EnergyPartials is read back.
// The header must come back unchanged and each block's largest item be the oracle's (integers);
// the sums are float: a block's kinetic and potential energy are compared as the error against
// the oracle's (its terms added in double, rounded once) over the sum of the terms' magnitudes,
// at most 1e-6: a tree of eight levels of float additions is off by at most 8 x 2^-24 = 4.8e-7 of
// that (identical terms on openmp and CUDA; a Vulkan division may put a term an ulp or two off),
// and a sum that lost or doubled one item of 256 is off by far more. The largest item's kinetic
// energy: relative 1e-6. Cases: no item, one body, one particle, random bodies (static ones
// included) and particles (pinned ones included) over one and many blocks, cloth and rope
// particles, far from the origin (the reference point near the scene), every item at rest and
// equal items (the lowest must be named), and items that are not finite (they count nothing).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "shared/energy.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

/// Error of a block's sum over the sum of its terms' magnitudes (see the file's comment).
constexpr double kEnergySumTolerance = 1.0e-6;
/// Relative error of a block's largest item kinetic energy.
constexpr double kEnergyLargestTolerance = 1.0e-6;

float as_float(uint bits) { return std::bit_cast<float>(bits); }

/// The header of EnergyPartials: x_ref's float bits and a 0.
std::vector<uint> header_at(vec3 ref) {
  return {std::bit_cast<uint>(ref.x), std::bit_cast<uint>(ref.y), std::bit_cast<uint>(ref.z), 0u};
}

/// The lowest particle of a world along its gravity (the point the host would choose), or the
/// origin without particles.
vec3 lowest_point(const World& w) {
  vec3 best(0.0f);
  double lowest = std::numeric_limits<double>::infinity();
  const vec4 g = w.params.gravity_dt;
  for (const vec4& x : w.particles.pos) {
    const double h = -(static_cast<double>(g.x) * static_cast<double>(x.x) +
                       static_cast<double>(g.y) * static_cast<double>(x.y) +
                       static_cast<double>(g.z) * static_cast<double>(x.z));
    if (h < lowest) {
      lowest = h;
      best = vec3(x.x, x.y, x.z);
    }
  }
  return best;
}

class EnergyReduce : public DeviceTest {
 protected:
  void run_case(const std::string& layout, const World& w, vec3 ref) {
    const std::vector<uint> header = header_at(ref);
    const motes_ref::EnergyBlocks want =
        motes_ref::energy_reduce(w.particles, w.bodies, w.params, header);
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::BodyPos, Buffer::BodyVel,
                        Buffer::BodyAngVel, Buffer::BodyAngMom}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVel, w.bodies.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngVel, w.bodies.angvel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngMom, w.bodies.angmom));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::EnergyPartials, header));  // the blocks stay poisoned
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::EnergyReduce, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<uint> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::EnergyPartials, got));
    ASSERT_EQ(got.size(), want.words.size());

    const std::size_t blocks = want.kinetic_abs.size();
    std::vector<uint> indices, want_indices;
    double kinetic = 0.0, potential = 0.0, largest = 0.0;
    for (std::size_t k = 0; k < blocks; ++k) {
      const std::size_t at = MOTES_ENERGY_HEADER + MOTES_ENERGY_WORDS * k;
      indices.push_back(got[at + MOTES_ENERGY_MAX_ITEM]);
      want_indices.push_back(want.words[at + MOTES_ENERGY_MAX_ITEM]);
      const auto error = [&](std::size_t word, double scale) {
        const double a = as_float(got[at + word]);
        const double b = as_float(want.words[at + word]);
        if (a == b) return 0.0;
        if (!std::isfinite(a)) return std::numeric_limits<double>::infinity();
        return std::abs(a - b) / std::max(scale, 1e-30);
      };
      kinetic = std::max(kinetic, error(MOTES_ENERGY_KINETIC, want.kinetic_abs[k]));
      potential = std::max(potential, error(MOTES_ENERGY_POTENTIAL, want.potential_abs[k]));
      largest =
          std::max(largest, error(MOTES_ENERGY_MAX_KINETIC,
                                  std::abs(as_float(want.words[at + MOTES_ENERGY_MAX_KINETIC]))));
    }
    begin_case("energy_reduce/" + layout,
               motes::shared::energy_items(w.params.body_count, w.params.particle_count,
                                           w.params.rigid_particle_count));
    check_identical("EnergyPartials header (the reference point)",
                    std::vector<uint>(got.begin(), got.begin() + MOTES_ENERGY_HEADER), header);
    check_identical("EnergyPartials largest item of each block", indices, want_indices);
    check_at_most("EnergyPartials kinetic energy of each block", "|error| / sum |terms|", kinetic,
                  kEnergySumTolerance);
    check_at_most("EnergyPartials potential energy of each block", "|error| / sum |terms|",
                  potential, kEnergySumTolerance);
    check_at_most("EnergyPartials largest item kinetic energy", "relative", largest,
                  kEnergyLargestTolerance);
    end_case();
  }
};

/// random_world with about one free particle in ten pinned (inverse mass 0).
World energy_world(std::uint32_t seed, std::size_t n) {
  World w = random_world(seed, n);
  Rng rng(seed + 2000u);
  for (std::size_t i = w.particles.rigid; i < w.particles.size(); ++i) {
    if (rng.chance(0.1f)) w.particles.vel[i].w = 0.0f;
  }
  return w;
}

/// The items of a world, and how many of them count (dynamic).
std::pair<std::size_t, std::size_t> items_of(const World& w) {
  std::size_t dynamic = 0;
  for (const vec4& b : w.bodies.pos) dynamic += b.w > 0.0f ? 1u : 0u;
  for (std::size_t i = w.particles.rigid; i < w.particles.size(); ++i) {
    dynamic += w.particles.vel[i].w > 0.0f ? 1u : 0u;
  }
  return {w.bodies.size() + (w.particles.size() - w.particles.rigid), dynamic};
}

TEST_P(EnergyReduce, Empty) { run_case("empty", random_world(501, 0), vec3(0.0f)); }

TEST_P(EnergyReduce, OneBody) {
  // One particle makes one rigid body (random_world keeps 70% rigid, rounded up).
  World w = random_world(502, 1);
  w.bodies.pos[0].w = 2.5f;
  ASSERT_EQ(items_of(w), std::make_pair(std::size_t{1}, std::size_t{1}));
  run_case("one_body", w, lowest_point(w));
}

TEST_P(EnergyReduce, OneParticle) {
  // The same particle as a free sphere: no body, one particle item.
  World w = random_world(503, 1);
  w.bodies = motes_ref::Bodies{};
  w.bodies.first.push_back(0u);
  w.particles.rigid = 0;
  w.particles.local.clear();
  w.particles.vel[0].w = 800.0f;
  w.sizes.bodies = 0;
  w.sizes.rigid_particles = 0;
  w.params.body_count = 0;
  w.params.rigid_particle_count = 0;
  ASSERT_EQ(items_of(w), std::make_pair(std::size_t{1}, std::size_t{1}));
  run_case("one_particle", w, lowest_point(w));
}

TEST_P(EnergyReduce, Random31) {
  const World w = energy_world(504, 31);
  run_case("random", w, lowest_point(w));
}

TEST_P(EnergyReduce, Random1234) {
  const World w = energy_world(505, 1234);
  // More than one block, static bodies and pinned particles among them.
  const auto [items, dynamic] = items_of(w);
  ASSERT_GT(items, std::size_t{MOTES_ENERGY_BLOCK});
  ASSERT_LT(dynamic, items);
  run_case("random", w, lowest_point(w));
}

TEST_P(EnergyReduce, Random65537) {
  // 65,537 particles: the last block is partial.
  const World w = energy_world(506, 65537);
  run_case("random", w, lowest_point(w));
}

TEST_P(EnergyReduce, Linked) {
  // Cloth and rope particles after the rigid ones count as particles.
  const World w = with_linked(energy_world(507, 1234), 507);
  run_case("linked", w, lowest_point(w));
}

TEST_P(EnergyReduce, FarFromOrigin) {
  // The scene 1e5 m from the origin, the reference point at its lowest particle: potential
  // energies of the scene's own size, not of 1e5 m.
  World w = energy_world(508, 1234);
  for (vec4& x : w.particles.pos) {
    x.x += 1.0e5f;
    x.y -= 2.0e5f;
    x.z += 3.0e5f;
  }
  for (vec4& x : w.bodies.pos) {
    x.x += 1.0e5f;
    x.y -= 2.0e5f;
    x.z += 3.0e5f;
  }
  run_case("far_from_origin", w, lowest_point(w));
  const motes_ref::EnergyBlocks e =
      motes_ref::energy_reduce(w.particles, w.bodies, w.params, header_at(lowest_point(w)));
  for (std::size_t k = 0; k < e.potential_abs.size(); ++k) {
    // Heights of at most the cloud's side (centimetres) times 9.81 and masses of grams: far
    // below what 2e5 m would give.
    EXPECT_LT(e.potential_abs[k], 10.0) << "block " << k;
  }
}

TEST_P(EnergyReduce, AtRest) {
  // Every item at rest: kinetic 0 everywhere, and each block names its first counting item.
  World w = energy_world(509, 1234);
  for (vec4& v : w.particles.vel) v = vec4(0.0f, 0.0f, 0.0f, v.w);
  for (vec4& v : w.bodies.vel) v = vec4(0.0f);
  for (vec4& v : w.bodies.angvel) v = vec4(0.0f);
  for (vec4& v : w.bodies.angmom) v = vec4(0.0f);
  run_case("at_rest", w, lowest_point(w));
}

TEST_P(EnergyReduce, EqualItems) {
  // The free particles all alike and faster than any body: the lowest of them wins every block.
  World w = energy_world(510, 4000);
  for (std::size_t i = w.particles.rigid; i < w.particles.size(); ++i) {
    w.particles.vel[i] = vec4(3.0f, -4.0f, 1.0f, 700.0f);
  }
  run_case("equal_items", w, lowest_point(w));
  const motes_ref::EnergyBlocks e =
      motes_ref::energy_reduce(w.particles, w.bodies, w.params, header_at(lowest_point(w)));
  const std::size_t last = e.kinetic_abs.size() - 1;
  EXPECT_EQ(e.words[MOTES_ENERGY_HEADER + MOTES_ENERGY_WORDS * last + MOTES_ENERGY_MAX_ITEM],
            last * MOTES_ENERGY_BLOCK);
}

TEST_P(EnergyReduce, NonFinite) {
  // A NaN velocity, an infinite position, a NaN inverse mass and an infinite angular momentum:
  // those items count nothing (particles_check names them), the others as always.
  World w = energy_world(511, 4000);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t nr = w.particles.rigid;
  w.particles.vel[nr + 5].y = nan;
  w.particles.pos[nr + 300].z = -inf;
  w.particles.vel[nr + 301].w = nan;
  w.bodies.angmom[7] = vec4(inf, 0.0f, 0.0f, 0.0f);
  w.bodies.pos[7].w = 1.0f;
  w.bodies.vel[9].x = nan;
  w.bodies.pos[9].w = 1.0f;
  run_case("non_finite", w, lowest_point(w));
}

INSTANTIATE_TEST_SUITE_P(Conformance, EnergyReduce, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
