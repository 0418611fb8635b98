// Parameter structs shared by the core, every backend and the shaders (std430 / push-constant
// layout). Any change here must keep the static_asserts true on all three sides.
#ifndef MOTES_SHARED_PARAMS_H
#define MOTES_SHARED_PARAMS_H

#include "common.h"

MOTES_SHARED_BEGIN

/// StepParams.flags: the normal force may not become attractive (clamped dashpot).
#define MOTES_FLAG_CLAMP_ATTRACTION 1u
/// StepParams.flags: rigid bodies meet each other and the planes with impulses (shared/impulse.h),
/// so contacts_compute leaves those contacts out (every other contact keeps the force law).
#define MOTES_FLAG_IMPULSE 2u
/// impulses_compute / impulses_apply: the counting pass. Count each body's contacts, keep its
/// velocities as the stage's start (BodyVelStart, BodyAngVelStart) and apply the warm start
/// (each contact's accumulated impulse of the last substep).
#define MOTES_FLAG_IMPULSE_COUNT 4u
/// bodies_integrate: only the velocities (v += dt (F/m + g), L += dt tau, w from L).
#define MOTES_FLAG_BODY_VELOCITY 8u
/// bodies_integrate: only the pose, from the velocities as they are (x += dt v, q from L).
#define MOTES_FLAG_BODY_POSE 16u
/// particles_update: first hand what the constraints did to each rigid particle to its body, as
/// an impulse (shared/body_math.h: particle_absorbed_impulse) into ParticleForce and its moment
/// into ParticleMoment (cloth and ropes attached to rigid bodies); then the pose as always.
/// impulses_apply: the impulses to apply are those (every particle may have one), not the
/// impulse stage's.
#define MOTES_FLAG_ABSORB 32u
/// constraints_solve: also ask for a neighbour-list rebuild when a particle it moved is too far
/// from where the lists were built. Set on the last sweep of a substep only: the positions of the
/// earlier sweeps are not the ones contacts see, and the test reads 32 B per projection more.
#define MOTES_FLAG_SKIN_CHECK 64u
/// impulses_compute: a relaxing sweep (shared/impulse.h, impulse_target).
#define MOTES_FLAG_IMPULSE_RELAX 128u
/// impulses_apply: keep the velocities this sweep leaves in BodyVelPush and BodyAngMomPush;
/// bodies_integrate with MOTES_FLAG_BODY_POSE: move with them. impulses_compute: write the
/// accumulated impulses to ContactImpulseSplit too (the last relaxing sweep of a split substep).
#define MOTES_FLAG_IMPULSE_PUSH 256u
/// Position contacts (shared/position.h, docs/architecture.md "Position contacts"):
/// impulses_compute projects the overlaps of the predicted poses (with MOTES_FLAG_IMPULSE_COUNT:
/// counts them); impulses_apply moves each body's pose by what its contacts ask and keeps the
/// motion as velocity; bodies_integrate predicts with gravity alone (no BodyForce, BodyTorque).
#define MOTES_FLAG_POSITION 512u
/// With MOTES_FLAG_POSITION, impulses_compute: the velocity pass (restitution, and the normal
/// velocity the projection left taken back) on the contacts the projection had.
#define MOTES_FLAG_POSITION_VELOCITY 1024u
/// With MOTES_FLAG_POSITION: the substep's first counting pass and projection sweep (a contact's
/// record of being projected this substep starts anew; impulses_apply keeps the velocities as the
/// substep's start).
#define MOTES_FLAG_POSITION_FIRST 2048u
/// particles_integrate: move each particle by the mean of the shifts contacts_compute summed with
/// MOTES_FLAG_POSITION (shared/particle_shift.h) and its velocity by that / dt; nothing else.
/// Without it, MOTES_FLAG_POSITION makes particles_integrate predict (gravity, no force).
#define MOTES_FLAG_PARTICLE_SHIFT 4096u
/// Split impulses (docs/architecture.md, "Impulse contacts"): impulses_compute, a correcting sweep
/// that reads and writes its accumulated impulses in ContactImpulseSplit (ContactImpulse keeps the
/// relaxed ones); bodies_integrate with MOTES_FLAG_BODY_POSE: the pose moves with BodyVel and
/// BodyAngMom (the corrected velocities), which then take BodyVelPush and BodyAngMomPush (the
/// relaxed ones) back (shared/body_math.h: body_split_pose).
#define MOTES_FLAG_IMPULSE_SPLIT 8192u
/// With MOTES_FLAG_POSITION and MOTES_FLAG_IMPULSE_COUNT (the counting pass before the last
/// projection sweep): impulses_compute gives each particle the sum of n n^T over its contacts
/// (ParticleForce.xyz its diagonal, w the count; ParticleMoment.xyz the rest), and impulses_apply
/// sums them over each body into the bound of its contacts' Gram matrix that the velocity pass
/// steps by (shared/contact_gram.h), in BodyAngVelStart.w.
#define MOTES_FLAG_POSITION_GRAM 16384u
/// fluid_velocity: the solid particles too (set by the core when a fluid's material has adhesion):
/// each takes the reaction to its fluid neighbours' adhesion (shared/fluid.h:
/// fluid_adhesion_reaction), a rigid particle's in ParticleForce (w 0) for its body, a free
/// particle's as its change of velocity. Without it, fluid_velocity runs over the fluid only.
#define MOTES_FLAG_FLUID_ADHESION 32768u

/// Launch parameters of every kernel family; travels with the launch (push constants).
struct StepParams {
  vec4 gravity_dt;            // xyz: gravity (m/s^2), w: time step of this substep (s)
  uint particle_count;        // N
  uint body_count;            // B: rigid bodies; they own particles [0, rigid_particle_count)
  uint table_mask;            // T - 1; the hashed grid has T = 2^k buckets
  uint plane_count;           // P
  float cell_size;            // grid cell edge (m) = max(largest diameter, largest fluid h) + skin
  float inv_cell_size;        // 1 / cell_size
  uint material_count;        // M; pair table has M*M entries
  uint flags;                 // MOTES_FLAG_*
  uint rigid_particle_count;  // Nr: particles [Nr, N) are free spheres, integrated as particles
  uint neighbour_capacity;    // K: list entries kept per particle
  float neighbour_skin;       // s (m): lists hold pairs closer than max(r_i + r_j, h) + s
  uint linked_first;          // Nl: particles [Nl, N) are cloth and rope particles (shared/links.h)
  float linked_damping;       // fraction of their velocity the linked particles lose per substep
  uint constraint_first;      // constraints_solve: the colour's first constraint
  uint constraint_count;      // constraints_solve: its number of constraints (relax: colours)
  uint soft_first;            // Ns: particles [Ns, Nl) are soft-body particles (shape matching)
  uint cluster_count;         // S: shape-matching clusters (shared/shape_matching.h)
  uint halo_particles;        // halo_pack, halo_unpack: particle entries (shared/halo.h)
  uint halo_bodies;           // halo_pack, halo_unpack: rigid body entries after them
  uint halo_first;            // halo_pack, halo_unpack: their first word in HaloIndex
  uint fluid_first;           // Nf: particles [Nf, Nf + fluid_count) are fluid (docs/fluids.md),
  uint fluid_count;           // a range of free particles ending at Ns; 0: no fluid
  uint neighbour_columns;     // Vulkan: list columns per storage buffer (0: one buffer holds all)
  uint constraint_sweeps;     // constraints_relax: its sweeps over every colour; 0 elsewhere
};

/// Contact law of one pair of materials (symmetric): F_n = k d - gamma_n m* v_n,
/// F_t = gamma_t m* v_t, |F_t| <= mu |F_n| when friction >= 0. Impulse contacts use the friction
/// and the restitution (shared/impulse.h).
struct ContactLaw {
  float stiffness;    // k (N/m)
  float damping;      // gamma_n (1/s), multiplied by the effective mass m*
  float tangential;   // gamma_t (1/s), multiplied by m*
  float friction;     // Coulomb cap mu; negative: no cap (Harada's purely viscous force)
  float restitution;  // e of impulse contacts, in [0, 1]
  float reserved0;    // 0
  float reserved1;    // 0
  float reserved2;    // 0
};

/// Static analytic half-space: solid where dot(normal, x) < offset.
struct PlaneData {
  vec4 normal_offset;  // xyz: unit normal pointing into free space, w: offset
  uint material;
  uint pad0;
  uint pad1;
  uint pad2;
};

MOTES_SHARED_END

#ifdef __cplusplus
static_assert(sizeof(motes::shared::StepParams) == 112, "StepParams layout");
static_assert(offsetof(motes::shared::StepParams, particle_count) == 16, "StepParams layout");
static_assert(offsetof(motes::shared::StepParams, flags) == 44, "StepParams layout");
static_assert(offsetof(motes::shared::StepParams, neighbour_skin) == 56, "StepParams layout");
static_assert(offsetof(motes::shared::StepParams, constraint_count) == 72, "StepParams layout");
static_assert(offsetof(motes::shared::StepParams, cluster_count) == 80, "StepParams layout");
// No padding bytes: queued calls are compared with memcmp to find the step's repeating cycle
// (kernel_queue.cpp), and a padding byte's garbage would hide it (every flush a new graph).
static_assert(offsetof(motes::shared::StepParams, fluid_first) == 96, "StepParams layout");
static_assert(offsetof(motes::shared::StepParams, constraint_sweeps) +
                      sizeof(motes::shared::uint) ==
                  sizeof(motes::shared::StepParams),
              "StepParams must have no padding");
static_assert(sizeof(motes::shared::ContactLaw) == 32, "ContactLaw layout");
static_assert(sizeof(motes::shared::PlaneData) == 32, "PlaneData layout");
#endif

#endif  // MOTES_SHARED_PARAMS_H
