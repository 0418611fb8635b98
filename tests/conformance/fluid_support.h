// What the fluid families' cases share (test_fluid_density.cpp, test_fluid_update.cpp,
// test_fluid_vorticity.cpp, test_fluid_velocity.cpp): a world of rigid bodies around a block of
// fluid, its oracle lists, and writing the families' inputs.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "conformance.h"
#include "motes/fluid.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {

/// The fluid's particle diameter d (m) and material (water; materials 0 and 1 have no fluid
/// entry).
constexpr float kFluidDiameter = 0.01f;
constexpr uint kFluidMaterial = 2;

struct FluidWorld {
  World w;
  std::vector<motes::shared::FluidMaterial> fluids;  ///< FluidMaterials (M = 3)
  std::vector<vec4> state;  ///< a FluidState to start from (random earlier Lambda_i)
  motes_ref::Grid grid;
  motes_ref::Neighbours nb;
};

/// make_world's rigid bodies (a random cloud of n particles, radii up to 5 mm) with its free
/// particles [Nr, N) made fluid: a cubic lattice of spacing `spacing` d from the cloud's middle,
/// each point moved by up to `jitter` d per axis, radius d / 2, inverse mass 1 / (rho_0 d^3),
/// material 2; a floor 0.3 d below the lattice and a wall 0.5 d beside it added to make_world's
/// planes; the cell max(2 rmax, h) + skin; lists of capacity 64; FluidMaterials from
/// motes::fluid_material at 16 substeps of 1/60 s; the oracle's grid and lists.
inline FluidWorld fluid_world(std::uint32_t seed, std::size_t n, float spacing, float jitter) {
  Rng rng(seed);
  const float rmax = 0.005f;
  const float side = dense_side(n, rmax);
  const vec3 origin(-0.02f, 0.01f, -0.03f);
  FluidWorld fw;
  fw.w = make_world(rng, random_cloud(rng, n, rmax, side, origin), 0, false, kTestSkin);
  World& w = fw.w;
  const auto nr = static_cast<uint>(w.particles.rigid);
  const auto count = static_cast<uint>(n) - nr;
  const uint per_side = std::max(1u, static_cast<uint>(std::ceil(std::cbrt(double(count)))));
  const float d = kFluidDiameter;
  const float step = spacing * d;
  const vec3 corner = origin + vec3(0.5f * side, 0.25f * side, 0.25f * side);
  motes::Material water;
  water.density = 1000.0;
  const motes::shared::FluidMaterial f = motes::fluid_material(water, d, 1.0 / 960.0);
  for (uint k = 0; k < count; ++k) {
    const uint i = nr + k;
    const float x = float(k % per_side), y = float((k / per_side) % per_side),
                z = float(k / (per_side * per_side));
    w.particles.pos[i] =
        vec4(corner.x + step * x + jitter * d * rng.uniform(-1.0f, 1.0f),
             corner.y + step * y + jitter * d * rng.uniform(-1.0f, 1.0f),
             corner.z + step * z + jitter * d * rng.uniform(-1.0f, 1.0f), 0.5f * d);
    w.particles.vel[i].w = 1.0f / f.density_h.z;
    w.particles.material[i] = kFluidMaterial;
  }
  PlaneData floor{};
  floor.normal_offset = vec4(0.0f, 1.0f, 0.0f, corner.y - 0.3f * d);
  PlaneData wall{};
  wall.normal_offset = vec4(1.0f, 0.0f, 0.0f, corner.x - 0.5f * d);
  wall.material = 1;
  w.planes.push_back(floor);
  w.planes.push_back(wall);
  w.sizes.planes = static_cast<std::uint32_t>(w.planes.size());
  w.sizes.neighbour_capacity = 64;
  w.sizes.fluid_particles = count;
  StepParams& p = w.params;
  p.plane_count = w.sizes.planes;
  p.neighbour_capacity = 64;
  p.fluid_first = nr;
  p.fluid_count = count;
  p.flags = MOTES_FLAG_POSITION;
  p.gravity_dt.w = 1.0f / 960.0f;
  p.cell_size = std::max(2.0f * rmax, f.density_h.y) + p.neighbour_skin;
  p.inv_cell_size = 1.0f / p.cell_size;
  if (count > 0) {  // without fluid particles FluidMaterials is empty (Sizes::fluid_particles)
    fw.fluids.assign(w.sizes.materials, motes::shared::FluidMaterial{});
    fw.fluids[kFluidMaterial] = f;
  }
  for (uint k = 0; k < count; ++k) {
    fw.state.emplace_back(rng.uniform(900.0f, 1100.0f), rng.uniform(-1e-6f, 0.0f),
                          rng.uniform(-1e-5f, 0.0f), 0.0f);
  }
  fw.grid = motes_ref::grid_build(w.particles, p);
  fw.nb = motes_ref::neighbours_build(w.particles, fw.grid, p);
  return fw;
}

/// fw with its first `solids` fluid particles made free solid particles (as a free sphere's, a
/// soft body's, a cloth's or a rope's: they react to the liquid with their own shift): the fluid
/// range starts after them, each keeps its place, its inverse mass is halved and its material is
/// 0; the oracle's grid and lists are built again for the new range.
inline void fluid_free_solids(FluidWorld& fw, uint solids) {
  StepParams& p = fw.w.params;
  solids = std::min(solids, p.fluid_count);
  for (uint k = 0; k < solids; ++k) {
    const uint i = p.fluid_first + k;
    fw.w.particles.vel[i].w *= 0.5f;
    fw.w.particles.material[i] = 0;
  }
  p.fluid_first += solids;
  p.fluid_count -= solids;
  fw.w.sizes.fluid_particles = p.fluid_count;
  fw.state.erase(fw.state.begin(), fw.state.begin() + solids);
  fw.grid = motes_ref::grid_build(fw.w.particles, p);
  fw.nb = motes_ref::neighbours_build(fw.w.particles, fw.grid, p);
}

/// The velocity-level parameters of the stirred cases: XSPH c 0.1, vorticity eps 0.5 m/s,
/// cohesion gamma 0.5, adhesion beta 2 (each term a visible part of the change of velocity).
inline const vec4 kFluidStirParameters(0.1f, 0.5f, 0.5f, 2.0f);

/// The fluid particles of fw set in motion for the velocity-level families: a rigid rotation
/// of `spin` rad/s about the y axis through the block's mean position, plus a seeded uniform
/// noise of up to `noise` m/s per axis; and the fluid material's velocity-level parameters
/// `velocity` = (XSPH c, vorticity eps, cohesion gamma, adhesion beta).
inline void fluid_stir(FluidWorld& fw, std::uint32_t seed, float spin, float noise, vec4 velocity) {
  const StepParams& p = fw.w.params;
  motes_ref::Particles& particles = fw.w.particles;
  double mx = 0.0, mz = 0.0;
  for (uint k = 0; k < p.fluid_count; ++k) {
    mx += double(particles.pos[p.fluid_first + k].x);
    mz += double(particles.pos[p.fluid_first + k].z);
  }
  const double count = std::max(1.0, double(p.fluid_count));
  const auto cx = static_cast<float>(mx / count), cz = static_cast<float>(mz / count);
  Rng rng(seed);
  for (uint k = 0; k < p.fluid_count; ++k) {
    vec4& v = particles.vel[p.fluid_first + k];
    const vec4 x = particles.pos[p.fluid_first + k];
    v.x = spin * (x.z - cz) + noise * rng.uniform(-1.0f, 1.0f);
    v.y = noise * rng.uniform(-1.0f, 1.0f);
    v.z = -spin * (x.x - cx) + noise * rng.uniform(-1.0f, 1.0f);
  }
  if (!fw.fluids.empty()) fw.fluids[kFluidMaterial].velocity = velocity;
}

/// Component c of every element, in x (the others 0): FluidState's rho, lambda and Lambda differ
/// by ten orders of magnitude, so each is compared on its own.
inline std::vector<vec4> component(const std::vector<vec4>& v, int c) {
  std::vector<vec4> out;
  for (const vec4& e : v)
    out.emplace_back(c == 0 ? e.x : c == 1 ? e.y : c == 2 ? e.z : e.w, 0.0f, 0.0f, 0.0f);
  return out;
}

/// The fluid families' fixtures: writing their inputs for lists of capacity K.
class FluidTest : public DeviceTest {
 protected:
  /// Allocates for capacity K, poisons all but the inputs, writes them with `state` as FluidState.
  void write_inputs(const FluidWorld& fw, uint capacity, const std::vector<vec4>& state) {
    motes::Sizes sizes = fw.w.sizes;
    sizes.neighbour_capacity = capacity;
    ASSERT_NO_FATAL_FAILURE(allocate(sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but(
        {Buffer::ParticlePos, Buffer::ParticleVel, Buffer::ParticleBody, Buffer::ParticleMaterial,
         Buffer::NeighbourList, Buffer::NeighbourCount, Buffer::NeighbourRefPos, Buffer::GridOrder,
         Buffer::GridCellStart, Buffer::SortedBody, Buffer::Planes, Buffer::LinkExclusions,
         Buffer::FluidMaterials, Buffer::FluidState}));
    const motes_ref::Particles& now = fw.w.particles;
    ASSERT_NO_FATAL_FAILURE(write(Buffer::LinkExclusions, fw.w.link_exclusions));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, now.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, now.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, now.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleMaterial, now.material));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourList, list_buffer(fw.nb, capacity)));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourCount, fw.nb.count));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, fw.nb.ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridOrder, fw.grid.order));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridCellStart, fw.grid.cell_start));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedBody, fw.grid.sorted_body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::Planes, fw.w.planes));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::FluidMaterials, fw.fluids));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::FluidState, state));
  }
  using Buffer = motes::Buffer;
};

}  // namespace motes_conf
