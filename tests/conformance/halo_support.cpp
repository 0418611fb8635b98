// What the halo cases share (halo_support.h).
#include "halo_support.h"

#include <iterator>
#include <utility>

namespace motes_conf {

namespace {

/// Bit patterns a copy must keep: NaNs with payloads (quiet, signalling), infinities, -0,
/// subnormals.
constexpr uint kSpecial[] = {0x7FC12345u, 0xFFA00001u, 0x7F800000u, 0xFF800000u,
                             0x80000000u, 0x00000001u, 0x807FFFFFu};
/// The finite ones, for positions (halo_unpack measures them against NeighbourRefPos).
constexpr uint kSpecialFinite[] = {0x80000000u, 0x00000001u, 0x807FFFFFu};

/// A component replaced by one of `patterns` now and then.
float maybe_special(Rng& rng, float x, const uint* patterns, std::size_t count) {
  if (!rng.chance(0.05f)) return x;
  return std::bit_cast<float>(patterns[rng.below(static_cast<std::uint32_t>(count))]);
}

/// The first `count` of a random permutation of [0, n).
std::vector<uint> scrambled(Rng& rng, std::size_t n, std::size_t count) {
  std::vector<uint> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<uint>(i);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t j = i + rng.below(static_cast<std::uint32_t>(n - i));
    std::swap(ids[i], ids[j]);
  }
  ids.resize(count);
  return ids;
}

}  // namespace

vec4 random_state(Rng& rng, float scale, bool finite) {
  const uint* patterns = finite ? kSpecialFinite : kSpecial;
  const std::size_t count = finite ? std::size(kSpecialFinite) : std::size(kSpecial);
  vec4 v(rng.uniform(-scale, scale), rng.uniform(-scale, scale), rng.uniform(-scale, scale),
         rng.uniform(0.0f, scale));
  v.x = maybe_special(rng, v.x, patterns, count);
  v.y = maybe_special(rng, v.y, patterns, count);
  v.z = maybe_special(rng, v.z, patterns, count);
  v.w = maybe_special(rng, v.w, patterns, count);
  return v;
}

/// New particle and body states for every particle and body of h (positions finite).
void randomize_state(Rng& rng, Halo& h) {
  for (vec4& x : h.particles.pos) x = random_state(rng, 1.0f, true);
  for (vec4& v : h.particles.vel) v = random_state(rng, 3.0f, false);
  for (std::vector<vec4> motes_ref::Bodies::*state : kHaloOracleBodyState) {
    for (vec4& v : h.bodies.*state) v = random_state(rng, 2.0f, false);
  }
}

/// `np` particle entries and `nb` body entries over twice as many particles and bodies (plus a
/// few), in scrambled order after 1 to 7 junk words (none when there are no entries).
/// `out_of_range`: three entries name a particle or body that does not exist.
Halo make_halo(std::uint32_t seed, std::size_t np, std::size_t nb, bool out_of_range) {
  Rng rng(seed);
  Halo h;
  const std::size_t n = 2 * np + 3;
  const std::size_t b = 2 * nb + 2;
  h.particles.pos.resize(n);
  h.particles.vel.resize(n);
  for (std::vector<vec4> motes_ref::Bodies::*state : kHaloOracleBodyState)
    (h.bodies.*state).resize(b);
  randomize_state(rng, h);

  const bool any = np + nb > 0;
  const std::size_t first = any ? 1 + rng.below(7) : 0;
  for (std::size_t k = 0; k < first; ++k) h.index.push_back(rng.below(static_cast<uint>(n)));
  for (const uint i : scrambled(rng, n, np)) h.index.push_back(i);
  for (const uint j : scrambled(rng, b, nb)) h.index.push_back(j);
  if (any) {
    for (int k = 0; k < 3; ++k) h.index.push_back(rng.below(static_cast<uint>(n)));
  }
  if (out_of_range && np > 2 && nb > 0) {
    h.index[first] = static_cast<uint>(n);  // the particle count itself
    h.index[first + np / 2] = 0xFFFFFFFFu;
    h.index[first + np + nb - 1] = static_cast<uint>(b);
  }

  h.sizes.particles = static_cast<std::uint32_t>(n);
  h.sizes.bodies = static_cast<std::uint32_t>(b);
  h.sizes.table = motes::grid_table_size(h.sizes.particles);
  h.sizes.halo_index = static_cast<std::uint32_t>(h.index.size());
  h.sizes.halo_data =
      static_cast<std::uint32_t>(MOTES_HALO_PARTICLE_VEC4S * np + MOTES_HALO_BODY_VEC4S * nb);
  StepParams& p = h.params;
  p.particle_count = h.sizes.particles;
  p.body_count = h.sizes.bodies;
  p.table_mask = h.sizes.table - 1;
  p.cell_size = 1.0f;
  p.inv_cell_size = 1.0f;
  p.neighbour_skin = kTestSkin;
  p.halo_first = static_cast<uint>(first);
  p.halo_particles = static_cast<uint>(np);
  p.halo_bodies = static_cast<uint>(nb);
  return h;
}

/// The particles an entry of h writes (in range), as a mask over particles.
std::vector<bool> named_particles(const Halo& h) {
  std::vector<bool> named(h.particles.size(), false);
  for (std::size_t k = 0; k < h.params.halo_particles; ++k) {
    const uint i = h.index[h.params.halo_first + k];
    if (i < h.particles.size()) named[i] = true;
  }
  return named;
}

}  // namespace motes_conf
