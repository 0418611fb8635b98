// Fixed-seed inputs for the kernel cases.
#include "test_data.h"

#include <algorithm>
#include <cmath>

#include "shared/links.h"
#include "shared/quaternion.h"

namespace motes_conf {

namespace {

/// A random unit quaternion (x, y, z, w).
vec4 random_quat(Rng& rng) {
  for (;;) {
    const double q[4] = {rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f),
                         rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f)};
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (norm < 0.1) continue;  // too short to normalize well
    return {static_cast<float>(q[0] / norm), static_cast<float>(q[1] / norm),
            static_cast<float>(q[2] / norm), static_cast<float>(q[3] / norm)};
  }
}

vec4 random_vec(Rng& rng, float scale, float w = 0.0f) {
  return {rng.uniform(-scale, scale), rng.uniform(-scale, scale), rng.uniform(-scale, scale), w};
}

/// Three materials. Deliberately asymmetric: the buffer's contract is laws[a * M + b] with a =
/// the particle's own material, and a symmetric table would hide swapped indices. Caps: none
/// (-1), zero (no tangential force at all) and finite; restitutions (impulse contacts) 0 to 0.9.
/// Dashpots strong enough that the normal force often turns attractive, so
/// MOTES_FLAG_CLAMP_ATTRACTION matters.
std::vector<ContactLaw> three_materials() {
  return {
      {200.0f, 400.0f, 300.0f, -1.0f, 0.0f, 0.0f, 0.0f, 0.0f},
      {300.0f, 800.0f, 1000.0f, 0.5f, 0.5f, 0.0f, 0.0f, 0.0f},
      {150.0f, 1500.0f, 2000.0f, 0.0f, 0.2f, 0.0f, 0.0f, 0.0f},
      {250.0f, 600.0f, 500.0f, 0.3f, 0.9f, 0.0f, 0.0f, 0.0f},
      {400.0f, 200.0f, 100.0f, -1.0f, 0.0f, 0.0f, 0.0f, 0.0f},
      {500.0f, 1000.0f, 3000.0f, 0.8f, 0.3f, 0.0f, 0.0f, 0.0f},
      {120.0f, 2000.0f, 1500.0f, 0.2f, 0.7f, 0.0f, 0.0f, 0.0f},
      {350.0f, 300.0f, 800.0f, -1.0f, 0.1f, 0.0f, 0.0f, 0.0f},
      {600.0f, 1200.0f, 400.0f, 0.4f, 0.4f, 0.0f, 0.0f, 0.0f},
  };
}

/// A plane with normal n that cuts into the cloud by half the largest radius: it touches the
/// particles of the cloud's surface on that side, as a wall does, with overlaps like those between
/// particles (a plane through the middle would push far harder and drown the pair forces).
PlaneData plane_at_surface(const std::vector<vec4>& pos, double nx, double ny, double nz,
                           uint material) {
  const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
  nx /= len;
  ny /= len;
  nz /= len;
  double lowest = 0.0;
  double rmax = 0.0;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const double d = nx * static_cast<double>(pos[i].x) + ny * static_cast<double>(pos[i].y) +
                     nz * static_cast<double>(pos[i].z);
    lowest = i == 0 ? d : std::min(lowest, d);
    rmax = std::max(rmax, static_cast<double>(pos[i].w));
  }
  PlaneData p{};
  p.normal_offset = vec4(static_cast<float>(nx), static_cast<float>(ny), static_cast<float>(nz),
                         static_cast<float>(lowest + 0.5 * rmax));
  p.material = material;
  return p;
}

/// A floor, a wall and (near the origin only) a tilted plane, each of another material.
std::vector<PlaneData> planes_around(const std::vector<vec4>& pos, bool tilted) {
  std::vector<PlaneData> out;
  out.push_back(plane_at_surface(pos, 0.0, 1.0, 0.0, 2));
  out.push_back(plane_at_surface(pos, -1.0, 0.0, 0.0, 1));
  if (tilted) out.push_back(plane_at_surface(pos, 1.0, 1.0, -1.0, 0));
  return out;
}

/// Appends one body's state: pose, velocities, inertia, force and torque (random), at `centre`.
void add_body_state(Rng& rng, motes_ref::Bodies& b, vec3 centre, float inv_mass) {
  b.pos.emplace_back(centre, inv_mass);
  b.quat.push_back(random_quat(rng));
  b.vel.push_back(random_vec(rng, 1.0f));
  // Some bodies do not turn at all (L = 0 and no torque) or too slowly for a rotation step
  // (|w dt| < 1e-12): both branches of body_integrate run.
  const float spin = rng.unit();
  const bool still = spin < 0.1f;
  b.angmom.push_back(still ? vec4(0.0f) : random_vec(rng, spin < 0.15f ? 1e-15f : 1e-3f));
  b.angvel.push_back(random_vec(rng, 20.0f));
  b.inv_inertia.emplace_back(rng.uniform(1e3f, 1e5f), rng.uniform(1e3f, 1e5f),
                             rng.uniform(1e3f, 1e5f), 0.0f);
  b.force.push_back(random_vec(rng, 1.0f));
  b.torque.push_back(still ? vec4(0.0f) : random_vec(rng, spin < 0.15f ? 1e-20f : 1e-2f));
}

}  // namespace

std::vector<vec4> random_cloud(Rng& rng, std::size_t n, float rmax, float side, vec3 origin) {
  std::vector<vec4> out;
  for (std::size_t i = 0; i < n; ++i) {
    out.emplace_back(origin.x + rng.uniform(0.0f, side), origin.y + rng.uniform(0.0f, side),
                     origin.z + rng.uniform(0.0f, side),
                     i == 0 ? rmax : rng.uniform(0.5f * rmax, rmax));
  }
  return out;
}

float dense_side(std::size_t n, float rmax) {
  // Mean contact distance 1.5 rmax: a sphere of 14.1 rmax^3 around each particle holds about 4.
  return static_cast<float>(std::cbrt(3.53 * static_cast<double>(n))) * rmax;
}

std::vector<vec4> on_cell_faces(Rng& rng, std::size_t n, float rmax, float skin) {
  const float cell = 2.0f * rmax + skin;
  std::vector<vec4> out;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t mode = rng.below(3);  // 3, 2 or 1 coordinates on a face
    const float a = static_cast<float>(static_cast<int>(rng.below(9)) - 4) * cell;
    const float free_b = rng.uniform(-4.0f * cell, 4.0f * cell);
    const float free_c = rng.uniform(-4.0f * cell, 4.0f * cell);
    const float b =
        mode >= 2 ? free_b : static_cast<float>(static_cast<int>(rng.below(9)) - 4) * cell;
    const float c =
        mode >= 1 ? free_c : static_cast<float>(static_cast<int>(rng.below(9)) - 4) * cell;
    const float r = i % 2 == 0 ? rmax : rng.uniform(0.5f * rmax, rmax);
    if (i % 3 == 0) out.emplace_back(a, b, c, r);  // rotate which coordinate is on a face
    if (i % 3 == 1) out.emplace_back(c, a, b, r);
    if (i % 3 == 2) out.emplace_back(b, c, a, r);
  }
  return out;
}

std::vector<vec4> one_cell(Rng& rng, std::size_t n, float rmax, vec3 corner, float skin) {
  const float cell = 2.0f * rmax + skin;
  std::vector<vec4> out;
  for (std::size_t i = 0; i < n; ++i) {
    out.emplace_back(corner.x + rng.uniform(0.05f, 0.95f) * cell,
                     corner.y + rng.uniform(0.05f, 0.95f) * cell,
                     corner.z + rng.uniform(0.05f, 0.95f) * cell,
                     i == 0 ? rmax : rng.uniform(0.5f * rmax, rmax));
  }
  return out;
}

std::vector<vec4> with_huge_coordinates(Rng& rng, std::size_t n, float rmax) {
  std::vector<vec4> out = random_cloud(rng, n, rmax, dense_side(n, rmax), vec3(0.0f));
  // Beyond 2^30 cells the index clamps; 3e38 * (1 / cell) overflows to infinity, which clamps too.
  const float huge[] = {1.0e7f, -1.0e7f, 3.0e9f, -3.0e9f, 1.0e30f, -1.0e30f, 3.0e38f, -3.0e38f};
  for (std::size_t k = 0; k < out.size() && k < 3 * std::size(huge); ++k) {
    const std::size_t i = (k * 7919) % out.size();
    const float h = huge[k % std::size(huge)];
    if (k % 3 == 0) out[i].x = h;
    if (k % 3 == 1) out[i].y = h;
    if (k % 3 == 2) out[i].z = h;
  }
  return out;
}

World make_world(Rng& rng, std::vector<vec4> positions, std::uint32_t flags, bool tilted_plane,
                 float skin) {
  World w;
  const std::size_t n = positions.size();
  const std::size_t rigid = n - n * 3 / 10;
  motes_ref::Particles& p = w.particles;
  motes_ref::Bodies& b = w.bodies;
  p.pos = std::move(positions);
  p.vel.resize(n);
  p.local.resize(rigid);
  p.body.resize(n);
  p.material.resize(n);
  p.rigid = rigid;
  for (std::size_t i = 0; i < rigid;) {
    // Runs of 1 (60%), 2-8 (30%) or 9-64 (10%) particles make one body.
    const float kind = rng.unit();
    std::size_t len = 1;
    if (kind > 0.9f) {
      len = 9 + rng.below(56);
    } else if (kind > 0.6f) {
      len = 2 + rng.below(7);
    }
    len = std::min(len, rigid - i);
    const bool is_static = rng.chance(0.1f);
    const float inv_particle_mass = is_static ? 0.0f : rng.uniform(500.0f, 2000.0f);
    const auto body = static_cast<uint>(b.first.size());
    b.first.push_back(static_cast<uint>(i));
    double centre[3] = {0.0, 0.0, 0.0};
    for (std::size_t k = i; k < i + len; ++k) {
      p.vel[k] = random_vec(rng, 1.0f, inv_particle_mass);
      p.local[k] = random_vec(rng, 0.05f);
      p.body[k] = body;
      p.material[k] = rng.below(3);
      centre[0] += static_cast<double>(p.pos[k].x) / static_cast<double>(len);
      centre[1] += static_cast<double>(p.pos[k].y) / static_cast<double>(len);
      centre[2] += static_cast<double>(p.pos[k].z) / static_cast<double>(len);
    }
    add_body_state(rng, b,
                   vec3(static_cast<float>(centre[0]), static_cast<float>(centre[1]),
                        static_cast<float>(centre[2])),
                   inv_particle_mass / static_cast<float>(len));
    // Body-frame offsets that put each particle where it is (to rounding): impulse contacts take
    // a particle's place from its body's pose (shared/impulse.h: contact_particle).
    for (std::size_t k = i; k < i + len; ++k) {
      const vec3 r = motes::shared::xyz(p.pos[k]) - motes::shared::xyz(b.pos.back());
      p.local[k] = vec4(motes::shared::quat_rotate_inverse(b.quat.back(), r), 0.0f);
    }
    i += len;
  }
  b.first.push_back(static_cast<uint>(rigid));
  for (std::size_t i = rigid; i < n; ++i) {  // free spheres
    p.vel[i] = random_vec(rng, 1.0f, rng.uniform(500.0f, 2000.0f));
    p.body[i] = static_cast<uint>(b.pos.size() + (i - rigid));
    p.material[i] = rng.below(3);
  }

  w.laws = three_materials();
  w.planes = planes_around(p.pos, tilted_plane);

  float cell = 0.0f;
  for (const vec4& x : p.pos) cell = std::max(cell, 2.0f * x.w);
  if (n == 0) cell = 1.0f;
  cell += skin;
  w.sizes.particles = static_cast<std::uint32_t>(n);
  w.sizes.rigid_particles = static_cast<std::uint32_t>(rigid);
  w.sizes.bodies = static_cast<std::uint32_t>(b.pos.size());
  w.sizes.neighbour_capacity = 16;
  w.sizes.table = motes::grid_table_size(w.sizes.particles);
  w.sizes.materials = 3;
  w.sizes.planes = static_cast<std::uint32_t>(w.planes.size());

  StepParams& sp = w.params;
  // Every gravity component non-zero, so that mixed-up components show.
  sp.gravity_dt = vec4(0.3f, -9.81f, 0.2f, 1.0e-3f);
  sp.particle_count = w.sizes.particles;
  sp.body_count = w.sizes.bodies;
  sp.table_mask = w.sizes.table - 1;
  sp.plane_count = w.sizes.planes;
  sp.cell_size = cell;
  sp.inv_cell_size = static_cast<float>(1.0 / static_cast<double>(cell));
  sp.material_count = w.sizes.materials;
  sp.flags = flags;
  sp.rigid_particle_count = w.sizes.rigid_particles;
  sp.neighbour_capacity = w.sizes.neighbour_capacity;
  sp.neighbour_skin = skin;
  return w;
}

World random_bodies(std::uint32_t seed, std::size_t bodies) {
  Rng rng(seed);
  World w;
  for (std::size_t k = 0; k < bodies; ++k) {
    const bool is_static = rng.chance(0.1f);
    add_body_state(
        rng, w.bodies,
        vec3(rng.uniform(-1.0f, 1.0f), rng.uniform(0.0f, 2.0f), rng.uniform(-1.0f, 1.0f)),
        is_static ? 0.0f : rng.uniform(0.5f, 50.0f));
  }
  w.bodies.first.assign(bodies + 1, 0u);  // no particles
  w.laws = three_materials();
  w.sizes.bodies = static_cast<std::uint32_t>(bodies);
  w.sizes.table = motes::grid_table_size(0);
  w.sizes.materials = 3;
  w.params.gravity_dt = vec4(0.3f, -9.81f, 0.2f, 1.0e-3f);
  w.params.body_count = w.sizes.bodies;
  w.params.table_mask = w.sizes.table - 1;
  w.params.cell_size = 1.0f;
  w.params.inv_cell_size = 1.0f;
  w.params.material_count = 3;
  return w;
}

std::vector<uint> list_buffer(const motes_ref::Neighbours& nb, uint capacity) {
  const std::size_t n = nb.count.size();
  std::vector<uint> out(std::size_t{capacity} * n, 0xFFFFFFFFu);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < std::min<std::size_t>(nb.lists[i].size(), capacity); ++k) {
      out[k * n + i] = nb.lists[i][k];
    }
  }
  return out;
}

std::vector<vec4> random_forces(std::uint32_t seed, std::size_t n, float scale) {
  Rng rng(seed);
  std::vector<vec4> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(random_vec(rng, scale));
  return out;
}

std::vector<vec4> moved_by(Rng& rng, const std::vector<vec4>& pos, float skin, float fraction) {
  std::vector<vec4> out = pos;
  for (vec4& x : out) {
    vec4 d = random_vec(rng, 1.0f);
    while (d.x * d.x + d.y * d.y + d.z * d.z < 0.01f) d = random_vec(rng, 1.0f);
    const float len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    const float s = fraction * skin / len;
    x = vec4(x.x + d.x * s, x.y + d.y * s, x.z + d.z * s, x.w);
  }
  return out;
}

World with_linked(World w, std::uint32_t seed) {
  Rng rng(seed);
  motes_ref::Particles& p = w.particles;
  for (std::size_t i = p.rigid; i < p.size(); ++i) {
    p.body[i] = motes::shared::linked_body(rng.below(3), rng.below(6), rng.below(6));
  }
  w.params.linked_first = static_cast<uint>(p.rigid);
  w.params.soft_first = w.params.linked_first;  // no soft bodies
  w.params.linked_damping = 0.25f;
  return w;
}

World with_mesh_linked(World w, std::uint32_t seed) {
  Rng rng(seed);
  motes_ref::Particles& p = w.particles;
  const std::size_t nl = p.rigid;
  const std::size_t n = p.size();
  std::vector<uint> object(n, 0u);
  uint vertices[2] = {0u, 0u};
  for (std::size_t i = nl; i < n; ++i) {
    object[i] = rng.below(2);
    p.body[i] = motes::shared::linked_mesh_body(object[i], vertices[object[i]]++);
  }
  float rmax = 0.0f;
  for (const vec4& x : p.pos) rmax = std::max(rmax, x.w);
  const float reach = 3.0f * rmax;
  for (std::size_t i = nl; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const float dx = p.pos[i].x - p.pos[j].x, dy = p.pos[i].y - p.pos[j].y;
      const float dz = p.pos[i].z - p.pos[j].z;
      if (object[i] != object[j] || dx * dx + dy * dy + dz * dz >= reach * reach) continue;
      if (rng.below(2) == 0) continue;
      p.never_touch.insert({uint(i), uint(j)});
      p.never_touch.insert({uint(j), uint(i)});
    }
  }
  // The buffer: a start for every linked particle, then the lists (a set's order: ascending).
  std::vector<uint> lists;
  w.link_exclusions.assign(1, 0u);
  auto at = p.never_touch.begin();
  for (std::size_t i = nl; i < n; ++i) {
    for (; at != p.never_touch.end() && at->first == i; ++at) lists.push_back(at->second);
    w.link_exclusions.push_back(static_cast<uint>(lists.size()));
  }
  w.link_exclusions.insert(w.link_exclusions.end(), lists.begin(), lists.end());
  w.sizes.link_exclusions = static_cast<uint>(w.link_exclusions.size());
  w.params.linked_first = static_cast<uint>(nl);
  w.params.soft_first = w.params.linked_first;  // no soft bodies
  w.params.linked_damping = 0.25f;
  return w;
}

World random_world(std::uint32_t seed, std::size_t n, std::uint32_t flags, float skin) {
  Rng rng(seed);
  const float rmax = 0.005f;
  std::vector<vec4> pos =
      random_cloud(rng, n, rmax, dense_side(n, rmax), vec3(-0.02f, 0.01f, -0.03f));
  return make_world(rng, std::move(pos), flags, true, skin);
}

double max_distance(const std::vector<vec4>& a, const std::vector<vec4>& b) {
  double worst = a.size() == b.size() ? 0.0 : HUGE_VAL;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    const double dx = static_cast<double>(a[i].x) - static_cast<double>(b[i].x);
    const double dy = static_cast<double>(a[i].y) - static_cast<double>(b[i].y);
    const double dz = static_cast<double>(a[i].z) - static_cast<double>(b[i].z);
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    worst = std::isnan(d) ? HUGE_VAL : std::max(worst, d);
  }
  return worst;
}

double coordinate_ulp(const std::vector<vec4>& pos) {
  float largest = 0.0f;
  for (const vec4& x : pos) {
    largest = std::max({largest, std::abs(x.x), std::abs(x.y), std::abs(x.z)});
  }
  return static_cast<double>(std::nextafter(largest, HUGE_VALF) - largest);
}

}  // namespace motes_conf
