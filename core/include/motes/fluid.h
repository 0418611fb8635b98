// Position-based fluids (issue 29, docs/fluids.md): the host side of a fluid material, the
// FluidMaterials entry every fluid family reads (shared/fluid.h: FluidMaterial), from the
// parameters settled with the serial prototype (docs/fluids.md, "Settled with the prototype").
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "motes/api.h"
#include "motes/scene.h"
#include "motes/status.h"
#include "shared/fluid.h"

MOTES_API_BEGIN
namespace motes {

/// A fluid particle's support h in diameters: h = 2 d (docs/fluids.md, "Support radius and the
/// neighbour lists"; shared/neighbours.h's MOTES_FLUID_SUPPORT_RADII is the same, in radii).
constexpr double kFluidSupportDiameters = 2.0;
/// Substeps of a step with fluid when the scene does not give them (16 x 2 sweeps of 1/60 s
/// steps met the hydrostatic bounds).
constexpr int kFluidSubsteps = 16;
/// Jacobi sweeps of the density constraint per substep (settings `fluid_iterations`'s default;
/// SceneFluid.SettingsDefaultToTheSettledSetWithFluid checks that they agree).
constexpr int kFluidIterations = 2;
/// List entries per particle in a scene with fluid when the scene does not give them (a fluid
/// particle at rest has 32 neighbours within h + skin).
constexpr int kFluidNeighbourCapacity = 64;
/// alpha~ as a fraction of a lattice particle's denominator at rest (Jacobi's under-relaxation:
/// stable above 0.41).
constexpr double kFluidRelaxation = 0.5;
/// s_corr's k at the reference substep kFluidReferenceSubstep; k of another substep h_s is
/// k h_s / kFluidReferenceSubstep (0.015 at 16 substeps of 1/60 s, 0.03 at 8: docs/fluids.md).
constexpr double kFluidScorrK = 0.015;
constexpr double kFluidReferenceSubstep = 1.0 / 960.0;
constexpr int kFluidScorrPower = 4;       ///< s_corr's n
constexpr double kFluidScorrDq = 0.2;     ///< s_corr's dq / h
constexpr double kFluidSolidScale = 1.0;  ///< psi_b = s rho_0 d_b^3

/// The spacing of the cubic lattice whose particles (diameter d, mass rho_0 d^3, h = 2 d) have the
/// rest density rho_0 by the poly6 sum: 1.003075 d. On the lattice of spacing d the sum is
/// 1.0098 rho_0, and the density constraint would push such a fill apart in its first substeps
/// (0.1 m/s in a block of a few centimetres: energy from nowhere). Scene fills use it.
double fluid_rest_spacing(double diameter);

/// The potential energy of the artificial pressure (s_corr) between two fluid particles of
/// material f at distance r (J), stepped in `sweeps` sweeps of substeps h_s: s_corr moves each of
/// them by a central repulsion in every sweep, the force m dx / h_s^2 of this pair potential
/// (u(r) = int_r^h |F|, 0 from h on). At a free surface the repulsion turns it into motion: it is
/// the energy a block of liquid has besides its motion and its height (docs/fluids.md, "Energy").
double fluid_s_corr_energy(double r, const shared::FluidMaterial& f, double substep, int sweeps);

/// A fluid particle's mass, rho_0 d^3 (rho_0 the material's rest_density, else its density): the
/// rest lattice of spacing d holds the rest density.
double fluid_particle_mass(const Material& m, double diameter);

/// The denominator sum_k w_k |grad_k C_i|^2 of a particle of the rest lattice (spacing d, h = 2 d,
/// mass rho_0 d^3: grad_i C_i vanishes by symmetry, so (m / rho_0^2) sum_j |grad W_ij|^2 =
/// 0.3734 m / (rho_0^2 d^8)), summed in double over the lattice.
double fluid_rest_denominator(double rest_density, double diameter);

/// The FluidMaterials entry of a fluid of material m (rest_density, or density when 0), particles
/// of diameter d, stepped at substeps of h_s: rho_0, h = 2 d, m = rho_0 d^3,
/// alpha~ = kFluidRelaxation D_rest; k (kFluidScorrK scaled to h_s), n, dq = 0.2 h, s = 1; the
/// material's viscosity, vorticity, cohesion and adhesion.
shared::FluidMaterial fluid_material(const Material& m, double diameter, double substep);

/// An emitter's particles on the device (docs/fluids.md, "Emitters"): [first, first + count) in
/// device order, parked (inverse mass 0) until they leave in the emitter's order; inverse_mass is
/// theirs once they have.
struct EmitterRange {
  std::size_t entry = 0;  ///< the fluid's scene entry (Simulation::bodies)
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  float inverse_mass = 0.0f;
  float radius = 0.0f;  ///< their radius (ParticlePos w)
  FluidEmitter emitter;
  std::uint64_t emitted = 0;  ///< particles that have left, a prefix of the range
};

/// How many of an emitter's particles have left by the start of a step at time t: whole layers
/// (one each layer_period from start, none at or after stop), at most max_particles.
std::uint64_t emitter_particles_by(const FluidEmitter& e, double t);

/// The hash of the particles' radii and inverse masses (the w of ParticlePos and ParticleVel, in
/// device order) that a checkpoint must match, an emitter's particles counted at their inverse
/// mass once emitted whether they have left or not.
std::uint64_t particle_w_hash(std::span<const shared::vec4> pos, std::span<const shared::vec4> vel,
                              std::span<const EmitterRange> emitters);

/// The FluidMaterials table of a scene: one entry per material (scene.materials' order), that of a
/// fluid's material from fluid_material, the others 0. Fails when two fluids of one material have
/// different diameters (the entry holds one h and one mass).
Result<std::vector<shared::FluidMaterial>> fluid_materials(const Scene& scene, double substep);

}  // namespace motes
MOTES_API_END
