// The energy guard on the host (docs/reliability.md, "Guards while running"): a state's
// mechanical energy from a Snapshot, the scene's stored contact energy, and the reference E0 and
// margin the guard compares against. Simulation::check_motion measures the energy on the device
// (Device::energy_reduce, the same definition in shared/energy.h) and uses these for the rest;
// a run over MPI ranks checks rank 0's gathered Snapshot with them.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/scene.h"
#include "shared/params.h"

MOTES_API_BEGIN
namespace motes {

struct Snapshot;  // motes/simulation.h
struct BodyInfo;

/// The mechanical energy of a state (J), in double. Items as on the device (shared/energy.h):
/// every dynamic rigid body (BodyPos.w > 0: 0.5 m |v|^2 + 0.5 omega.L) and every particle of a
/// free sphere, soft body, cloth or rope whose inverse mass ParticleVel.w > 0 (0.5 m |v|^2); the
/// potential energy of each is -m g.(x - reference). Static bodies and pinned particles count
/// nothing, nor does an item that is not finite.
struct MechanicalEnergy {
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  double kinetic = 0.0;
  double potential = 0.0;
  /// The item with the most kinetic energy (the first such in the scene's order): its kinetic
  /// energy, its scene body, and for a particle item its scene particle index (kNone for a rigid
  /// body; kNone for both when no item counts).
  double largest_kinetic = 0.0;
  std::uint32_t largest_body = kNone;
  std::uint32_t largest_particle = kNone;
  [[nodiscard]] double total() const { return kinetic + potential; }
};

/// mechanical_energy of `state` (Simulation::snapshot, DistributedSimulation::gather), whose
/// bodies are `bodies` (Simulation::bodies: a rigid body counts by its body state, a soft body,
/// cloth or rope by its particles; a free sphere's body state is its particle's).
MechanicalEnergy mechanical_energy(const Snapshot& state, std::span<const BodyInfo> bodies,
                                   const Eigen::Vector3d& gravity,
                                   const Eigen::Vector3d& reference);

/// What the energy guard needs to know about a scene besides its state, built once from the scene
/// (energy_model): which particles touch with which law (as the device decides it:
/// shared/contact_force.h, shared/links.h), in the scene's particle order, and the masses that
/// bound a particle's speed.
struct EnergyModel {
  /// Per scene particle: the word shared::contact_excluded compares (its scene body; a cloth's or
  /// rope's particle: shared::linked_body or shared::linked_mesh_body of its object), its
  /// material, and whether it is a rigid body's in a scene with impulse contacts (its contacts
  /// with other such particles and with the planes are impulses: no spring stores energy), or any
  /// particle's in a scene of position contacts (no force law at all).
  std::vector<std::uint32_t> contact_word;
  std::vector<std::uint32_t> material;
  std::vector<std::uint8_t> by_impulse;
  /// Cloths made from meshes: for every scene particle, where its list of the scene particles
  /// within two links starts (particles + 1 entries; empty without such a cloth), then the lists,
  /// ascending. Those never touch.
  std::vector<std::uint32_t> exclusion_start;
  std::vector<std::uint32_t> exclusion_list;
  std::vector<shared::ContactLaw> laws;  ///< materials x materials (contact_law_table)
  std::uint32_t materials = 0;
  std::vector<shared::PlaneData> planes;
  /// The mass of every dynamic body and unpinned cloth or rope particle (kg).
  double dynamic_mass = 0.0;
  /// The lightest item that can move: a dynamic rigid body, or a particle of a free sphere, soft
  /// body, cloth or rope (kg; 0 when nothing can move).
  double lightest_mass = 0.0;
  /// The factor s of the speed bound: no particle of an item of mass m and kinetic energy K is
  /// faster than c sqrt(2 K / m), c = 1 for a particle and sqrt(1 + m lambda) for a rigid body
  /// (lambda: the largest eigenvalue of I^-1 (|r|^2 1 - r r^T) over its particles' offsets r), so
  /// none is faster than s sqrt(2 K_max / lightest_mass) with s = the largest c sqrt(lightest /
  /// m) over the items (docs/reliability.md).
  double speed_factor = 1.0;
  double largest_diameter = 0.0;  ///< of any particle (m)
  double substep = 0.0;           ///< dt / substeps (s)
};

/// The energy model of a scene (its bodies, cloths and ropes in the order Simulation::create and
/// a Snapshot give them).
EnergyModel energy_model(const Scene& scene);

/// The energy stored in the springs of the contact law in `state` (J): 0.5 k overlap^2 for every
/// overlapping pair of particles that touch (of different bodies, not excluded as neighbours of a
/// cloth or rope, at least one of them dynamic, not two particles of rigid bodies under impulse
/// contacts) and for every dynamic particle overlapping a plane (not a rigid one under impulse
/// contacts). A hash grid of cells of the largest diameter: O(N).
double contact_energy(const Snapshot& state, const EnergyModel& model);

/// The fraction f of the start's energy scale that the energy guard's margin allows above E0
/// (docs/reliability.md gives the largest rises measured in the example scenes and the physics
/// tests).
constexpr double kEnergyMarginFraction = 0.1;
/// The fraction of the kinetic energy at a check that the margin allows on top: single-precision
/// rounding of the velocities drifts the energy of fast motion (a free fall of 10 s at dt 0.1 ms
/// gains 0.16% of its kinetic energy; docs/reliability.md).
constexpr double kEnergyMotionFraction = 0.05;
/// Units in the last place of the largest coordinate that the margin's rounding floor lets the
/// dynamic mass move per substep: the velocities of cloth, rope and soft-body particles come from
/// position corrections divided by the substep, so they carry about an ulp of the coordinates
/// per substep of rounding noise even at rest (docs/reliability.md).
constexpr double kEnergyRoundingUlps = 16.0;
/// The factor on the energy speed bound for single-precision rounding (speeds and energies are
/// floats: their own error is about 1e-6).
constexpr double kEnergySpeedSlack = 1.01;

/// What the energy guard compares against: E0 and the margin above it (docs/reliability.md).
struct EnergyReference {
  std::uint64_t step = 0;  ///< the state it was taken at
  double time = 0.0;
  double kinetic = 0.0;    ///< kinetic energy then (J)
  double potential = 0.0;  ///< potential energy then, from the reference point (J)
  double contact = 0.0;    ///< contact_energy then (scenes with the contact law)
  /// sum m |g| (h - h_lowest) over the dynamic items, h along -g, h_lowest the lowest particle
  /// then: the potential energy the scene could still release by falling (J).
  double height = 0.0;
  /// The margin's floor: the dynamic mass lifted by the largest particle diameter, M |g| d_max,
  /// plus that mass moving kEnergyRoundingUlps ulps of the largest coordinate X then per substep,
  /// 0.5 M (16 ulp(X) / h)^2 (what rounding alone makes of the energy of a scene at rest).
  double floor = 0.0;
  /// The fixed part of the margin: kEnergyMarginFraction x (kinetic + contact + height) + floor
  /// (J).
  double margin = 0.0;
  /// E0: the energy the state had, its stored contact energy included.
  [[nodiscard]] double energy() const { return kinetic + potential + contact; }
  /// The margin at a check whose kinetic energy is `kinetic_now`: margin + kEnergyMotionFraction
  /// x kinetic_now.
  [[nodiscard]] double margin_at(double kinetic_now) const {
    return margin + kEnergyMotionFraction * std::max(0.0, kinetic_now);
  }
  /// The most energy the guard lets the scene have at that check.
  [[nodiscard]] double limit(double kinetic_now) const { return energy() + margin_at(kinetic_now); }
};

/// The reference at `state`, whose kinetic and potential energy (from the reference point) are
/// `measured` (the device's, or mechanical_energy's).
EnergyReference energy_reference(const Snapshot& state, std::span<const BodyInfo> bodies,
                                 const EnergyModel& model, const Eigen::Vector3d& gravity,
                                 const MechanicalEnergy& measured);

/// The fastest any particle can move while the energy guard holds (m/s): no item has more
/// kinetic energy than all of it, K, and the guard holds while K + potential <= E0 + margin +
/// kEnergyMotionFraction K, so K <= (E0 + margin - potential) / (1 - kEnergyMotionFraction); the
/// bound is kEnergySpeedSlack x model.speed_factor x sqrt(2 K / lightest_mass), `potential` the
/// state's potential energy from the same reference point as the reference's; infinity when
/// nothing can move.
double energy_speed_limit(const EnergyReference& reference, const EnergyModel& model,
                          double potential);

/// Where a run stands when its energy guard speaks: for the errors' text.
struct GuardPlace {
  std::uint64_t step = 0;
  double time = 0.0;
  double dt = 0.0;
  int substeps = 1;
};

/// The energy guard's error when kinetic + potential (from the reference's point) is above
/// reference.limit(kinetic) or not finite (docs/reliability.md), naming the step, the energies,
/// E0 and the margin, and `who` (the body and particle with the most kinetic energy); "" when the
/// energy holds.
std::string energy_error(const EnergyReference& reference, double kinetic, double potential,
                         const GuardPlace& at, const std::string& who);

/// The speed bound's error when `speed` (particle `particle` of body `body` named `name`) is above
/// `limit` (energy_speed_limit with `potential`); "" otherwise.
std::string energy_speed_error(const EnergyReference& reference, const EnergyModel& model,
                               double potential, double speed, double limit, std::uint32_t particle,
                               std::uint32_t body, const std::string& name, const GuardPlace& at);

}  // namespace motes
MOTES_API_END
