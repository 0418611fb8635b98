// The hashed grid and the gathered contact forces of the OpenMP device, against brute force.
//
// For random particles (sizes 0, 1, 31, 1234, 20000; all in one cell; on cell faces, with an
// inexact and an exact cell size; 1000 m from the origin; mixed radii; static particles;
// multi-particle bodies) the device's grid_build must give exactly:
//  - GridBucket[i] = grid_bucket(cell of particle i) (shared/grid_hash.h),
//  - GridOrder = particle ids stably sorted by bucket (std::stable_sort here),
//  - GridCellStart[b] = number of particles in buckets < b, for b = 0..T (so bucket b's
//    particles are GridOrder[GridCellStart[b] .. GridCellStart[b+1]), and the last entry is N),
//  - Sorted{Pos,Vel,Body,Material}[k] = Particle*[GridOrder[k]], bitwise;
// the overlapping pairs found by visiting the 27 neighbouring cells through those buckets must be
// exactly the pairs an O(N^2) search finds; and contacts_compute must give every dynamic
// particle the sum of particle_contact_force over its overlapping particles of other bodies plus
// plane_contact_force over the planes (static particles: exactly 0).
//
// Force tolerance: each term is computed by the same shared function from the same floats, so
// terms agree bitwise and only the summation order differs. Summing K float terms in any order
// errs by at most (K - 1) u sum|f_k| + O(u^2), u = 2^-24; the reference sums in double. The test
// allows K u sum|f_k| per component (and requires exactly 0 when K = 0).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "motes/backend/device.h"
#include "motes/devices.h"
#include "sanitized_build.h"
#include "shared/contact_force.h"
#include "shared/grid_hash.h"
#include "shared/params.h"

namespace {

using motes::shared::ContactLaw;
using motes::shared::PlaneData;
using motes::shared::vec3;
using motes::shared::vec4;
using Pair = std::pair<std::uint32_t, std::uint32_t>;

constexpr std::uint32_t kMaterials = 2;

struct Particles {
  std::vector<vec4> pos;  // xyz, w = radius
  std::vector<vec4> vel;  // xyz, w = inverse mass
  std::vector<std::uint32_t> body;
  std::vector<std::uint32_t> material;
  std::vector<std::uint32_t> body_first;  // B + 1 entries
};

/// Fills velocities, inverse masses, bodies (contiguous runs, some static) and materials.
void assign_attributes(Particles& p, std::mt19937& rng) {
  std::uniform_real_distribution<float> v(-1.0f, 1.0f);
  std::uniform_real_distribution<float> inv_mass(500.0f, 2000.0f);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  const std::size_t n = p.pos.size();
  p.vel.resize(n);
  p.body.resize(n);
  p.material.resize(n);
  p.body_first.clear();
  float body_inv_mass = 0.0f;
  for (std::size_t i = 0; i < n; ++i) {
    // A new body starts with probability 0.7: runs of 1 to a few particles share a body.
    if (i == 0 || u01(rng) < 0.7f) {
      p.body_first.push_back(static_cast<std::uint32_t>(i));
      body_inv_mass = u01(rng) < 0.1f ? 0.0f : inv_mass(rng);
    }
    p.body[i] = static_cast<std::uint32_t>(p.body_first.size() - 1);
    p.vel[i] = vec4(v(rng), v(rng), v(rng), body_inv_mass);
    p.material[i] = u01(rng) < 0.5f ? 0u : 1u;
  }
  p.body_first.push_back(static_cast<std::uint32_t>(n));
}

/// Uniform positions in a cube of side `side` at `origin`, radii in [rmax/2, rmax].
Particles random_cloud(std::size_t n, float rmax, float side, vec3 origin, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> x(0.0f, side);
  std::uniform_real_distribution<float> r(0.5f * rmax, rmax);
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    p.pos.emplace_back(origin.x + x(rng), origin.y + x(rng), origin.z + x(rng), r(rng));
  }
  if (n > 0) p.pos[0].w = rmax;  // the largest diameter sets the cell size
  assign_attributes(p, rng);
  return p;
}

/// Positions whose coordinates are whole multiples of the cell size (k * cell computed in
/// float), some with one or two coordinates left random: particles on faces, edges, corners.
Particles on_cell_faces(std::size_t n, float rmax, unsigned seed) {
  std::mt19937 rng(seed);
  const float cell = 2.0f * rmax;
  std::uniform_int_distribution<int> k(-4, 4);
  std::uniform_real_distribution<float> x(-4.0f * cell, 4.0f * cell);
  std::uniform_real_distribution<float> r(0.5f * rmax, rmax);
  std::uniform_int_distribution<int> mode(0, 3);
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    const int m = mode(rng);
    const float a = static_cast<float>(k(rng)) * cell;
    const float b = m >= 2 ? x(rng) : static_cast<float>(k(rng)) * cell;
    const float c = m >= 1 ? x(rng) : static_cast<float>(k(rng)) * cell;
    // Rotate which coordinate is on a face.
    if (i % 3 == 0) p.pos.emplace_back(a, b, c, i % 2 == 0 ? rmax : r(rng));
    if (i % 3 == 1) p.pos.emplace_back(c, a, b, i % 2 == 0 ? rmax : r(rng));
    if (i % 3 == 2) p.pos.emplace_back(b, c, a, i % 2 == 0 ? rmax : r(rng));
  }
  assign_attributes(p, rng);
  return p;
}

/// Every particle inside one cell (the cell whose corner is `corner`).
Particles one_cell(std::size_t n, float rmax, vec3 corner, unsigned seed) {
  std::mt19937 rng(seed);
  const float cell = 2.0f * rmax;
  std::uniform_real_distribution<float> x(0.05f * cell, 0.95f * cell);
  std::uniform_real_distribution<float> r(0.5f * rmax, rmax);
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    p.pos.emplace_back(corner.x + x(rng), corner.y + x(rng), corner.z + x(rng),
                       i == 0 ? rmax : r(rng));
  }
  assign_attributes(p, rng);
  return p;
}

std::vector<ContactLaw> contact_laws() {
  // Symmetric M x M table with distinct laws, one of them with a Coulomb cap.
  const ContactLaw l00{100.0f, 5.0f, 2.0f, -1.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  const ContactLaw l01{200.0f, 3.0f, 1.0f, 0.4f, 0.0f, 0.0f, 0.0f, 0.0f};
  const ContactLaw l11{150.0f, 4.0f, 3.0f, 0.2f, 0.0f, 0.0f, 0.0f, 0.0f};
  return {l00, l01, l01, l11};
}

std::vector<PlaneData> planes_through(const Particles& p) {
  // A horizontal plane and a tilted one, both cutting through the cloud.
  vec3 lo(1e30f), hi(-1e30f);
  for (const vec4& x : p.pos) {
    lo = vec3(std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z));
    hi = vec3(std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z));
  }
  if (p.pos.empty()) lo = hi = vec3(0.0f);
  const vec3 mid = (lo + hi) * 0.5f;
  const float floor_y = lo.y + 0.3f * (hi.y - lo.y);
  const float s = 1.0f / std::sqrt(3.0f);
  const vec3 tilt(s, s, -s);
  PlaneData floor{vec4(0.0f, 1.0f, 0.0f, floor_y), 1u, 0u, 0u, 0u};
  PlaneData tilted{vec4(tilt, motes::shared::dot(tilt, mid)), 0u, 0u, 0u, 0u};
  return {floor, tilted};
}

/// The overlap test of particle_contact_force, in the same float arithmetic.
bool overlapping(const vec4& a, const vec4& b) {
  const vec3 d = motes::shared::xyz(b) - motes::shared::xyz(a);
  const float dist2 = motes::shared::dot(d, d);
  const float rsum = a.w + b.w;
  return dist2 < rsum * rsum;
}

template <typename T>
std::vector<T> read_all(motes::Device& dev, motes::Buffer b, const motes::Sizes& sizes) {
  const motes::BufferLayout layout = motes::buffer_layout(b, sizes);
  std::vector<T> out(layout.count);
  const motes::Status st = dev.read(b, out.data(), layout.bytes());
  EXPECT_TRUE(st) << motes::buffer_name(b) << ": " << st.message();
  return out;
}

template <typename T>
void write_all(motes::Device& dev, motes::Buffer b, const std::vector<T>& data) {
  const motes::Status st = dev.write(b, data.data(), data.size() * sizeof(T));
  ASSERT_TRUE(st) << motes::buffer_name(b) << ": " << st.message();
}

bool same_bytes(const vec4& a, const vec4& b) { return std::memcmp(&a, &b, sizeof(vec4)) == 0; }

void check_on_device(const Particles& p, std::uint32_t flags, const motes::DeviceOptions& options) {
  auto opened = motes::open_device("openmp", -1, options);
  ASSERT_TRUE(opened) << opened.message();
  motes::Device& dev = *opened.value();

  const auto n = static_cast<std::uint32_t>(p.pos.size());
  const std::vector<ContactLaw> laws = contact_laws();
  const std::vector<PlaneData> planes = planes_through(p);
  motes::Sizes sizes;
  sizes.particles = n;
  sizes.rigid_particles = n;
  sizes.neighbour_capacity = 16;
  sizes.bodies = static_cast<std::uint32_t>(p.body_first.size() - 1);
  sizes.table = motes::grid_table_size(n);
  sizes.materials = kMaterials;
  sizes.planes = static_cast<std::uint32_t>(planes.size());
  ASSERT_TRUE(dev.allocate(sizes));

  write_all(dev, motes::Buffer::ParticlePos, p.pos);
  write_all(dev, motes::Buffer::ParticleVel, p.vel);
  write_all(dev, motes::Buffer::ParticleBody, p.body);
  write_all(dev, motes::Buffer::ParticleMaterial, p.material);
  write_all(dev, motes::Buffer::ParticleLocal, std::vector<vec4>(n, vec4(0.0f)));
  write_all(dev, motes::Buffer::BodyFirst, p.body_first);
  std::vector<vec4> body_pos(sizes.bodies);
  for (std::uint32_t b = 0; b < sizes.bodies; ++b) {
    body_pos[b] = vec4(0.0f, 0.0f, 0.0f, p.vel[p.body_first[b]].w);
  }
  write_all(dev, motes::Buffer::BodyPos, body_pos);
  write_all(dev, motes::Buffer::BodyQuat,
            std::vector<vec4>(sizes.bodies, vec4(0.0f, 0.0f, 0.0f, 1.0f)));
  for (motes::Buffer b : {motes::Buffer::BodyVel, motes::Buffer::BodyAngMom,
                          motes::Buffer::BodyAngVel, motes::Buffer::BodyInvInertia}) {
    write_all(dev, b, std::vector<vec4>(sizes.bodies, vec4(0.0f)));
  }
  write_all(dev, motes::Buffer::ContactLaws, laws);
  write_all(dev, motes::Buffer::Planes, planes);

  float cell = 0.0f;
  for (const vec4& x : p.pos) cell = std::max(cell, 2.0f * x.w);
  if (n == 0) cell = 1.0f;
  motes::shared::StepParams params{};
  params.gravity_dt = vec4(0.0f, -9.81f, 0.0f, 1.0e-4f);
  params.particle_count = n;
  params.body_count = sizes.bodies;
  params.table_mask = sizes.table - 1;
  params.plane_count = sizes.planes;
  params.cell_size = cell;
  params.inv_cell_size = 1.0f / cell;
  params.material_count = kMaterials;
  params.flags = flags;
  params.rigid_particle_count = n;
  params.neighbour_capacity = sizes.neighbour_capacity;
  params.neighbour_skin = 0.0f;  // lists of exactly the touching pairs

  dev.enqueue(motes::Kernel::GridBuild, params);
  dev.enqueue(motes::Kernel::NeighboursBuild, params);
  dev.enqueue(motes::Kernel::ContactsCompute, params);
  ASSERT_TRUE(dev.synchronize());
  const auto bucket = read_all<std::uint32_t>(dev, motes::Buffer::GridBucket, sizes);
  const auto order = read_all<std::uint32_t>(dev, motes::Buffer::GridOrder, sizes);
  const auto start = read_all<std::uint32_t>(dev, motes::Buffer::GridCellStart, sizes);
  const auto sorted_pos = read_all<vec4>(dev, motes::Buffer::SortedPos, sizes);
  const auto sorted_body = read_all<std::uint32_t>(dev, motes::Buffer::SortedBody, sizes);
  const auto force = read_all<vec4>(dev, motes::Buffer::ParticleForce, sizes);

  // Integer outputs: exact.
  const std::uint32_t mask = params.table_mask;
  auto cell_of = [&](const vec4& x) {
    return std::array<int, 3>{motes::shared::grid_cell_coord(x.x, params.inv_cell_size),
                              motes::shared::grid_cell_coord(x.y, params.inv_cell_size),
                              motes::shared::grid_cell_coord(x.z, params.inv_cell_size)};
  };
  std::vector<std::uint32_t> want_bucket(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto c = cell_of(p.pos[i]);
    want_bucket[i] = motes::shared::grid_bucket(c[0], c[1], c[2], mask);
  }
  ASSERT_EQ(bucket, want_bucket) << "GridBucket";
  std::vector<std::uint32_t> want_order(n);
  std::iota(want_order.begin(), want_order.end(), 0u);
  std::stable_sort(want_order.begin(), want_order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return want_bucket[a] < want_bucket[b];
  });
  ASSERT_EQ(order, want_order) << "GridOrder";
  std::vector<std::uint32_t> want_start(std::size_t{sizes.table} + 1);
  for (std::uint32_t b = 0; b <= sizes.table; ++b) {
    want_start[b] =
        static_cast<std::uint32_t>(std::lower_bound(want_order.begin(), want_order.end(), b,
                                                    [&](std::uint32_t id, std::uint32_t key) {
                                                      return want_bucket[id] < key;
                                                    }) -
                                   want_order.begin());
  }
  ASSERT_EQ(start, want_start) << "GridCellStart";
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t i = want_order[k];
    ASSERT_TRUE(same_bytes(sorted_pos[k], p.pos[i])) << "SortedPos[" << k << "]";
    ASSERT_EQ(sorted_body[k], p.body[i]) << "SortedBody[" << k << "]";
  }

  // Neighbour pairs: 27 cells through the device's buckets vs O(N^2), exact sets.
  std::set<Pair> via_grid;
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto c = cell_of(p.pos[i]);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint32_t b = motes::shared::grid_bucket(c[0] + dx, c[1] + dy, c[2] + dz, mask);
          for (std::uint32_t k = start[b]; k < start[b + 1]; ++k) {
            const std::uint32_t j = order[k];
            if (j != i && overlapping(p.pos[i], sorted_pos[k])) {
              via_grid.emplace(std::min(i, j), std::max(i, j));
            }
          }
        }
      }
    }
  }
  std::vector<Pair> brute;
  const vec4* pos = p.pos.data();
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::uint32_t j = i + 1; j < n; ++j) {
      // Farther apart along x than the radii's sum: overlapping() would say no (its float
      // dx * dx alone reaches rsum * rsum), and 20,000 particles make 2e8 pairs.
      const float dx = pos[j].x - pos[i].x;
      const float rsum = pos[i].w + pos[j].w;
      if (dx >= rsum || -dx >= rsum) continue;
      if (overlapping(pos[i], pos[j])) brute.emplace_back(i, j);
    }
  }
  ASSERT_EQ(std::vector<Pair>(via_grid.begin(), via_grid.end()), brute) << "neighbour pairs";

  // Forces: brute-force sum in double, per-component bound K u sum|f|.
  std::vector<std::vector<std::uint32_t>> partners(n);
  for (const Pair& pr : brute) {
    partners[pr.first].push_back(pr.second);
    partners[pr.second].push_back(pr.first);
  }
  const double u = std::ldexp(1.0, -24);
  double err2 = 0.0;
  double ref2 = 0.0;
  std::size_t contacts = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const vec4& xi = p.pos[i];
    const vec4& vi = p.vel[i];
    if (vi.w == 0.0f) {
      ASSERT_TRUE(force[i].x == 0.0f && force[i].y == 0.0f && force[i].z == 0.0f)
          << "static particle " << i << " got a force";
      continue;
    }
    double sum[3] = {0.0, 0.0, 0.0};
    double abs_sum[3] = {0.0, 0.0, 0.0};
    std::size_t terms = 0;
    auto add = [&](vec3 f) {
      const float c[3] = {f.x, f.y, f.z};
      for (int a = 0; a < 3; ++a) {
        sum[a] += static_cast<double>(c[a]);
        abs_sum[a] += std::abs(static_cast<double>(c[a]));
      }
      ++terms;
    };
    for (std::uint32_t j : partners[i]) {
      if (p.body[j] == p.body[i]) continue;  // particles of one body never push each other
      const ContactLaw law = laws[p.material[i] * kMaterials + p.material[j]];
      add(motes::shared::particle_contact_force(
          motes::shared::xyz(xi), motes::shared::xyz(vi), xi.w, vi.w, motes::shared::xyz(p.pos[j]),
          motes::shared::xyz(p.vel[j]), p.pos[j].w, p.vel[j].w, law, flags));
    }
    for (const PlaneData& pl : planes) {
      const ContactLaw law = laws[p.material[i] * kMaterials + pl.material];
      const vec3 f = motes::shared::plane_contact_force(
          motes::shared::xyz(xi), motes::shared::xyz(vi), xi.w, vi.w, pl.normal_offset, law, flags);
      if (f.x != 0.0f || f.y != 0.0f || f.z != 0.0f) add(f);
    }
    contacts += terms;
    const float got[3] = {force[i].x, force[i].y, force[i].z};
    for (int a = 0; a < 3; ++a) {
      const double g = static_cast<double>(got[a]);
      const double bound = static_cast<double>(terms) * u * abs_sum[a];
      ASSERT_LE(std::abs(g - sum[a]), bound)
          << "particle " << i << " component " << a << ": device " << g << ", reference " << sum[a]
          << " (" << terms << " terms)";
      err2 += (g - sum[a]) * (g - sum[a]);
      ref2 += sum[a] * sum[a];
    }
  }
  std::printf(
      "[grid] N=%u, %d thread(s): %zu overlapping pairs, %zu force terms, force NMSE "
      "%.2e\n",
      n, options.cpu_threads, brute.size(), contacts, ref2 > 0.0 ? err2 / ref2 : 0.0);
}

/// On one thread, and on three threads with every loop split (even for N = 1): the outputs
/// must not depend on how the work is divided.
void check_grid_and_forces(const Particles& p, std::uint32_t flags) {
  motes::DeviceOptions one;
  one.cpu_threads = 1;
  ASSERT_NO_FATAL_FAILURE(check_on_device(p, flags, one));
  motes::DeviceOptions three;
  three.cpu_threads = 3;
  three.cpu_min_parallel = 1;
  ASSERT_NO_FATAL_FAILURE(check_on_device(p, flags, three));
}

TEST(Grid, Empty) {
  Particles p;
  p.body_first = {0};
  check_grid_and_forces(p, 0u);
}

TEST(Grid, OneParticle) {
  check_grid_and_forces(random_cloud(1, 0.005f, 0.01f, vec3(0.0f), 1), 0u);
}

TEST(Grid, Random31) {
  check_grid_and_forces(random_cloud(31, 0.005f, 0.03f, vec3(-0.01f), 2), 0u);
}

TEST(Grid, Random1234Clamped) {
  check_grid_and_forces(random_cloud(1234, 0.005f, 0.11f, vec3(-0.05f), 3),
                        MOTES_FLAG_CLAMP_ATTRACTION);
}

TEST(Grid, Random20000) {
  // About one particle per cell volume: a couple of overlaps per particle. The sanitizer build
  // checks 5,000 at the same density (its brute-force reference at -O0 took 26 s for 20,000).
  const std::size_t n = motes_test::sanitized_or<std::size_t>(20000, 5000);
  const float edge = 0.27f * std::cbrt(static_cast<float>(n) / 20000.0f);
  check_grid_and_forces(random_cloud(n, 0.005f, edge, vec3(-0.1f, -0.2f, 0.03f), 4), 0u);
}

/// Number of distinct cells of edge `cell` the particles occupy.
std::size_t cell_count(const Particles& p, float cell) {
  const float inv = 1.0f / cell;
  std::set<std::array<int, 3>> cells;
  for (const vec4& x : p.pos) {
    cells.insert({motes::shared::grid_cell_coord(x.x, inv),
                  motes::shared::grid_cell_coord(x.y, inv),
                  motes::shared::grid_cell_coord(x.z, inv)});
  }
  return cells.size();
}

TEST(Grid, AllInOneCell) {
  const Particles p = one_cell(300, 0.005f, vec3(0.07f, -0.03f, 0.11f), 5);
  ASSERT_EQ(cell_count(p, 2.0f * 0.005f), 1u);
  check_grid_and_forces(p, 0u);
}

TEST(Grid, OnCellFacesInexactCell) {
  // cell = 0.01: k * cell is not exact in float, and floor(x / cell) decides the side.
  check_grid_and_forces(on_cell_faces(1234, 0.005f, 6), 0u);
}

TEST(Grid, OnCellFacesExactCell) {
  // cell = 0.5: every face coordinate is exact; touching particles (distance = r1 + r2) exist.
  check_grid_and_forces(on_cell_faces(1234, 0.25f, 7), MOTES_FLAG_CLAMP_ATTRACTION);
}

TEST(Grid, FarFromOrigin) {
  check_grid_and_forces(random_cloud(1234, 0.005f, 0.11f, vec3(1000.0f, -1000.0f, 1000.0f), 8), 0u);
}

TEST(Grid, FarFromOriginOneCell) {
  const Particles p = one_cell(200, 0.005f, vec3(-1000.0f, 1000.0f, -1000.0f), 9);
  ASSERT_EQ(cell_count(p, 2.0f * 0.005f), 1u);
  check_grid_and_forces(p, 0u);
}

}  // namespace
