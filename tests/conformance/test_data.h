// Inputs for the kernel cases: fixed-seed particle layouts and complete worlds (particles,
// bodies, contact laws, planes, launch parameters) built around them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "motes/backend/device.h"
#include "reference/reference.h"
#include "shared/common.h"
#include "shared/params.h"

namespace motes_conf {

using motes::shared::vec3;
using motes::shared::vec4;
using motes_ref::ContactLaw;
using motes_ref::PlaneData;
using motes_ref::StepParams;
using motes_ref::uint;

/// Floats from a fixed-seed std::mt19937's raw 32-bit output: the generator's sequence is fixed
/// by the standard, the std distributions' results are not (they differ between libraries).
class Rng {
 public:
  explicit Rng(std::uint32_t seed) : gen_(seed) {}
  /// Uniform in [0, 1), a multiple of 2^-24 (exact in float).
  float unit() { return static_cast<float>(gen_() >> 8) * (1.0f / 16777216.0f); }
  /// Uniform in [lo, hi).
  float uniform(float lo, float hi) { return lo + (hi - lo) * unit(); }
  /// Uniform integer in [0, n).
  std::uint32_t below(std::uint32_t n) {
    return static_cast<std::uint32_t>((std::uint64_t{gen_()} * n) >> 32);
  }
  bool chance(float p) { return unit() < p; }

 private:
  std::mt19937 gen_;
};

/// Everything a kernel can read: the oracle's host state plus the tables and launch parameters.
struct World {
  motes_ref::Particles particles;
  motes_ref::Bodies bodies;
  std::vector<ContactLaw> laws;  ///< M * M, at a * M + b
  std::vector<PlaneData> planes;
  StepParams params{};
  motes::Sizes sizes;
  std::vector<uint> link_exclusions;  ///< the LinkExclusions buffer (empty without a mesh cloth)
};

// Particle layouts: xyz = centre, w = radius (the largest radius, rmax, always occurs once).

/// Uniform in a cube of side `side` at `origin`, radii in [rmax/2, rmax].
std::vector<vec4> random_cloud(Rng& rng, std::size_t n, float rmax, float side, vec3 origin);
/// A cube side for random_cloud that gives about four overlapping neighbours per particle.
float dense_side(std::size_t n, float rmax);
/// Coordinates that are whole multiples of the cell size 2 rmax + skin (one, two or all three of
/// them): particles on cell faces, edges and corners, many touching or coincident.
std::vector<vec4> on_cell_faces(Rng& rng, std::size_t n, float rmax, float skin = 0.0f);
/// Every particle inside the one cell (edge 2 rmax + skin) whose lowest corner is `corner`.
std::vector<vec4> one_cell(Rng& rng, std::size_t n, float rmax, vec3 corner, float skin = 0.0f);
/// A random cloud plus particles at huge coordinates (up to 1e30 m), where the cell index clamps.
std::vector<vec4> with_huge_coordinates(Rng& rng, std::size_t n, float rmax);

/// Builds a world around `positions`: the first 70% of the particles make rigid bodies, runs of
/// consecutive particles (one particle to 64, about 10% static with inverse mass 0), the rest are
/// free spheres (dynamic, body B + k); random velocities, three materials with an asymmetric law
/// table (caps and no caps), planes touching the cloud, random body states; neighbour skin `skin`,
/// cell size = the largest diameter + skin, T = motes::grid_table_size(N), K = 16. The planes are a
/// floor and a wall, plus a tilted one when `tilted_plane`: far from the origin a tilted plane's
/// gap dot(n, x) - offset is only good to about ulp(|x|) (8 mm at 1e5 m), so fused and unfused
/// arithmetic may rightly disagree there; axis-aligned planes are exact at any distance.
World make_world(Rng& rng, std::vector<vec4> positions, std::uint32_t flags, bool tilted_plane,
                 float skin = 0.0f);

/// `bodies` bodies without particles (N = 0), for bodies_integrate: random poses, velocities,
/// angular momenta, inertia, forces and torques; about 10% static.
World random_bodies(std::uint32_t seed, std::size_t bodies);

/// Particles in a cloud of about `n` particles with random bodies (make_world).
World random_world(std::uint32_t seed, std::size_t n, std::uint32_t flags = 0, float skin = 0.0f);

/// The free particles of w [Nr, N) made cloth and rope particles: ParticleBody =
/// shared::linked_body of one of three objects at a random lattice place in [0, 6)^2 (so many
/// pairs are within two lattice steps: excluded from contact), linked_first = Nr, linked damping
/// 0.25 per substep.
World with_linked(World w, std::uint32_t seed);

/// The free particles of w [Nr, N) made particles of two cloths from meshes (ParticleBody =
/// shared::linked_mesh_body), with random never-touch pairs: each pair of one object closer than
/// 3 rmax is one with probability 1/2 (both ways), written as LinkExclusions lists and as the
/// oracle's set Particles::never_touch. linked_first = Nr.
World with_mesh_linked(World w, std::uint32_t seed);

/// The oracle's lists as a NeighbourList buffer of capacity K (entry k of particle i at k N + i;
/// unused entries 0xFFFFFFFF).
std::vector<uint> list_buffer(const motes_ref::Neighbours& nb, uint capacity);

/// n forces with components uniform in [-scale, scale), w = 0.
std::vector<vec4> random_forces(std::uint32_t seed, std::size_t n, float scale);

/// Elements [from, to) of v.
template <typename T>
std::vector<T> slice(const std::vector<T>& v, std::size_t from, std::size_t to) {
  return std::vector<T>(v.begin() + static_cast<std::ptrdiff_t>(from),
                        v.begin() + static_cast<std::ptrdiff_t>(to));
}

/// Each position moved by `fraction` * skin in a random direction (w kept): the positions of the
/// last neighbour-list build, as seen from `pos`, or later positions as seen from a build.
std::vector<vec4> moved_by(Rng& rng, const std::vector<vec4>& pos, float skin, float fraction);

/// Largest distance between corresponding xyz (HUGE_VAL when the sizes differ or one is NaN).
double max_distance(const std::vector<vec4>& a, const std::vector<vec4>& b);

/// One unit in the last place of the largest |coordinate| of `pos`: a position that rounds the
/// other way on another backend moves by this much, a Verlet velocity (x - x_prev) / dt by this
/// over dt.
double coordinate_ulp(const std::vector<vec4>& pos);

/// The skin the neighbour-list cases use with random_world's radii (rmax = 5 mm): 1 mm.
constexpr float kTestSkin = 0.001f;

}  // namespace motes_conf
