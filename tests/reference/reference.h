// The reference oracle: every kernel family of motes::Device (core/include/motes/backend/device.h)
// written as naive serial loops over host vectors, straight from its definition. Never optimized:
// it is what the conformance suite (tests/conformance/) compares every backend against.
//
// The per-particle and per-body math comes from the same shared headers the backends use
// (shaders/shared/), so the oracle checks each backend's scaffolding (indexing, sorting, ranges,
// neighbour search, summation, which buffers are read and written), not the physics formulas.
//
// One file per family, named after it (tests/reference/FAMILY.cpp, as the family's files on
// every backend); reference_common.cpp holds what several share (the whole step).
#pragma once

#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "shared/common.h"
#include "shared/fluid.h"
#include "shared/links.h"
#include "shared/params.h"
#include "shared/shape_matching.h"

namespace motes_ref {

using motes::shared::Cluster;
using motes::shared::ClusterFrame;
using motes::shared::ClusterMember;
using motes::shared::Constraint;
using motes::shared::ContactLaw;
using motes::shared::PlaneData;
using motes::shared::StepParams;
using motes::shared::uint;
using motes::shared::vec4;

/// Per-particle buffers (N each), as in motes::Buffer::Particle*: the rigid bodies' particles
/// [0, rigid) first, then free spheres.
struct Particles {
  std::vector<vec4> pos;       ///< xyz, w = radius
  std::vector<vec4> vel;       ///< xyz, w = inverse mass (0 = static)
  std::vector<vec4> local;     ///< (rigid) body-frame offset from the body's centre of mass
  std::vector<uint> body;      ///< body index (B + k for the k-th free sphere; cloth and rope:
                               ///< shared::linked_body)
  std::vector<uint> material;  ///< material index
  std::size_t rigid = 0;       ///< Nr: particles of rigid bodies
  /// Ordered pairs (i, j) of particles of a cloth made from a mesh that never touch: what the
  /// LinkExclusions lists hold (shared::linked_mesh_body words; the lists are a set here).
  std::set<std::pair<uint, uint>> never_touch;
  [[nodiscard]] std::size_t size() const { return pos.size(); }
};

/// Per-body buffers (B each), as in motes::Buffer::Body*; first has B + 1 entries.
struct Bodies {
  std::vector<vec4> pos;          ///< centre of mass, w = inverse mass (0 = static)
  std::vector<vec4> quat;         ///< orientation (x, y, z, w), body frame to world
  std::vector<vec4> vel;          ///< linear velocity
  std::vector<vec4> angmom;       ///< angular momentum (world)
  std::vector<vec4> angvel;       ///< angular velocity (world)
  std::vector<vec4> inv_inertia;  ///< inverse principal moments
  std::vector<vec4> force;        ///< summed contact force
  std::vector<vec4> torque;       ///< summed torque about the centre of mass
  std::vector<uint> first;        ///< first particle of each body, then N
  [[nodiscard]] std::size_t size() const { return pos.size(); }
};

/// Outputs of grid_build (GridBucket, GridOrder, GridCellStart, Sorted*).
struct Grid {
  std::vector<uint> bucket;      ///< N: bucket of particle i
  std::vector<uint> order;       ///< N: particle ids stably sorted by bucket
  std::vector<uint> cell_start;  ///< T + 1: first sorted position with bucket >= b; [T] = N
  std::vector<vec4> sorted_pos;
  std::vector<uint> sorted_body;
};

/// grid_build: bucket = shared::grid_bucket of the particle's cell (shared::grid_cell_coord with
/// p.inv_cell_size), order = std::stable_sort of the ids by bucket, the T = p.table_mask + 1
/// bucket starts, and copies of the particle data in that order.
Grid grid_build(const Particles& particles, const StepParams& p);

/// Outputs of neighbours_build (NeighbourList, NeighbourCount, NeighbourRefPos, NeighbourState).
struct Neighbours {
  std::vector<std::vector<uint>> lists;  ///< per particle, every neighbour in canonical order
  std::vector<uint> count;               ///< N: lists[i].size()
  std::vector<vec4> ref;                 ///< N: the positions it was built at
  uint over_capacity = 0;                ///< particles with more than K neighbours
  uint max_count = 0;                    ///< the largest count
};

/// The order in which the 27-cell walk from the cell of x visits buckets: the buckets of cells
/// (cx + dx, cy + dy, cz + dz) for dz = -1..1, dy = -1..1, dx = -1..1, each at its first
/// occurrence (the definition of docs/architecture.md, written without ranges or rows).
std::vector<uint> walk_buckets(vec4 x, const StepParams& p);

/// neighbours_build, by brute force: for every dynamic particle i, every particle j of another
/// body whose bucket is on i's walk and that shared::neighbour_within(i, j, skin) accepts, sorted
/// by (place of j's bucket on the walk, j's slot in grid.order); static particles get none.
/// ref = pos. over_capacity and max_count against p.neighbour_capacity.
Neighbours neighbours_build(const Particles& particles, const Grid& grid, const StepParams& p);

/// neighbours_update: when state[MOTES_NEIGHBOUR_REBUILD] (NeighbourState) is nonzero,
/// grid = grid_build and nb = neighbours_build, and true; otherwise nothing is written, and false.
bool neighbours_update(const Particles& particles, const std::vector<uint>& state,
                       const StepParams& p, Grid& grid, Neighbours& nb);

/// contacts_compute, by brute force over all pairs: the force on dynamic particle i is the sum,
/// over every particle j of another body, of shared::particle_contact_force with law
/// laws[material_i * M + material_j], plus shared::plane_contact_force of each plane with law
/// laws[material_i * M + plane.material]. Static particles (vel.w == 0) get 0. Indexed by
/// particle id; w = 0. Terms are summed in double, in id order, then rounded once to float: this
/// is the most accurate sum of the float terms, not the device's canonical order. With
/// MOTES_FLAG_POSITION the terms are shared::particle_contact_shift's and plane_contact_term's
/// shifts (h = p.gravity_dt.w; each particle's contacts within reach from `listed`, the lists'
/// counts, and the planes) and w is their number (shared/particle_shift.h): a rigid body's
/// particle takes rigid_contact_reaction of its contacts with other kinds' particles, whose
/// shifts take a rigid partner's inverse mass as 0. With MOTES_FLAG_IMPULSE a rigid body's particle
/// skips rigid partners and the planes (impulse_particle).
std::vector<vec4> contacts_compute(const Particles& particles, const std::vector<ContactLaw>& laws,
                                   const std::vector<PlaneData>& planes, const StepParams& p,
                                   const std::vector<uint>& listed = {});

/// bodies_reduce: force and torque (shared::particle_torque about the body's centre) of each
/// dynamic body, summed in float over its particles in particle order; static bodies get 0.
/// Writes bodies.force and bodies.torque (w = 0).
void bodies_reduce(const std::vector<vec4>& particle_pos, const std::vector<vec4>& particle_force,
                   Bodies& bodies);

/// bodies_integrate: shared::body_integrate on every body, with p.gravity_dt.
void bodies_integrate(Bodies& bodies, const StepParams& p);
/// bodies_integrate with MOTES_FLAG_BODY_POSE | MOTES_FLAG_IMPULSE_PUSH: shared::body_push_pose on
/// every body, moved with vel_push and angmom_push (BodyVelPush, BodyAngMomPush), the centre as
/// the pair pos + pos_low (BodyPosLow).
void bodies_push_pose(Bodies& bodies, std::vector<vec4>& pos_low, const std::vector<vec4>& vel_push,
                      const std::vector<vec4>& angmom_push, const StepParams& p);
/// bodies_integrate with MOTES_FLAG_BODY_POSE | MOTES_FLAG_IMPULSE_SPLIT: shared::body_split_pose
/// on every body (moved with its own velocities, which then take vel_push and angmom_push).
void bodies_split_pose(Bodies& bodies, std::vector<vec4>& pos_low,
                       const std::vector<vec4>& vel_push, const std::vector<vec4>& angmom_push,
                       const StepParams& p);

/// particles_update: ParticlePos/Vel xyz of the rigid particles [0, particles.rigid) from the body
/// pose (shared::particle_position and particle_velocity); w (radius, inverse mass) kept. Returns
/// whether one has moved too far from `ref` (shared::neighbour_moved_too_far); empty ref: false.
bool particles_update(const Bodies& bodies, Particles& particles, const StepParams& p,
                      const std::vector<vec4>& ref = {});

/// particles_update's first part with MOTES_FLAG_ABSORB: for each rigid particle [0, Nr),
/// shared::particle_absorbed_impulse of its velocity as it is (impulse, w = 0), or with
/// `reactions` (MOTES_FLAG_PARTICLE_SHIFT: ParticleForce as given) their xyz, and its moment
/// (R local) x impulse about the body's centre (moment, w = 0).
void absorbed_impulses(const Bodies& bodies, const Particles& particles, std::vector<vec4>& impulse,
                       std::vector<vec4>& moment, const std::vector<vec4>& reactions = {});

/// particles_check: the four MotionCheck words (shared/motion_check.h) over every particle, by
/// the definitions: the largest rate bits of a finite particle, the first finite particle with
/// them and its |v|^2 bits, the first particle that is not finite.
std::vector<uint> particles_check(const Particles& particles);

/// energy_reduce's EnergyPartials as the definition gives it (shared/energy.h): `header` (its
/// first MOTES_ENERGY_HEADER words: the reference point), then for every block of
/// MOTES_ENERGY_BLOCK items (bodies [0, p.body_count), then particles [p.rigid_particle_count,
/// p.particle_count)) the sums of its counting items' shared::item_energy, each added in double in
/// item order and rounded once to float (the most accurate sum of the float terms, not the
/// device's tree), its largest item kinetic energy and the first item with it (-1 and
/// MOTES_ENERGY_NONE when no item counts). Also, per block, the sums of the terms' magnitudes:
/// what a float sum's rounding error is bounded by.
struct EnergyBlocks {
  std::vector<uint> words;
  std::vector<double> kinetic_abs;
  std::vector<double> potential_abs;
};
EnergyBlocks energy_reduce(const Particles& particles, const Bodies& bodies, const StepParams& p,
                           const std::vector<uint>& header);

/// particles_integrate: shared::particle_integrate on the free particles [particles.rigid, N)
/// with `force`, the velocities of the linked ones [p.linked_first, N) first times 1 -
/// p.linked_damping (with MOTES_FLAG_POSITION the force is not used); with
/// MOTES_FLAG_PARTICLE_SHIFT instead shared::particle_shift_apply with `force` (the shifts' sum and
/// number); returns whether one has moved too far from `ref` (empty ref: false).
bool particles_integrate(Particles& particles, const std::vector<vec4>& force, const StepParams& p,
                         const std::vector<vec4>& ref = {});

/// constraints_solve: constraints [p.constraint_first, + p.constraint_count) projected one after
/// the other (shared::constraint_correction, constraint_apply); throws std::invalid_argument when
/// two of them share a particle (the colour would not be parallel). Returns whether a particle it
/// moved ends too far from `ref` (empty ref, or p.flags without MOTES_FLAG_SKIN_CHECK: false).
bool constraints_solve(Particles& particles, const std::vector<Constraint>& constraints,
                       const StepParams& p, const std::vector<vec4>& ref = {});

/// constraints_relax: p.constraint_sweeps sweeps, each over the colours [0, p.constraint_count)
/// of `colours` (colour k: constraints [colours[k], colours[k + 1])) in order, each colour as
/// constraints_solve; only the last sweep tests `ref` (with MOTES_FLAG_SKIN_CHECK). Returns
/// whether a particle it moved there ends too far from `ref`.
bool constraints_relax(Particles& particles, const std::vector<Constraint>& constraints,
                       const std::vector<uint>& colours, const StepParams& p,
                       const std::vector<vec4>& ref = {});

/// clusters_fit: for each cluster, its members' centre of mass (shared::cluster_centre_add) and
/// sums of positions and velocities (cluster_sums_add) in member order, in float as the device
/// does, then cluster_frame from the cluster's rotation in `frames`, and the third pass
/// (cluster_pull_add, cluster_frame_finish). Replaces `frames`.
void clusters_fit(const std::vector<vec4>& pos, const std::vector<vec4>& vel,
                  const std::vector<Cluster>& clusters, const std::vector<ClusterMember>& members,
                  std::vector<ClusterFrame>& frames);

/// clusters_goal: every particle in [p.soft_first, p.linked_first) damped by the sum of
/// shared::cluster_damp, then moved by the sum of cluster_shift over its members, found by scanning
/// all members in order (not through ClusterGather), its velocity by the same / dt
/// (constraint_apply). Returns whether one ends too
/// far from `ref` (empty ref: false).
bool clusters_goal(Particles& particles, const std::vector<ClusterMember>& members,
                   const std::vector<ClusterFrame>& frames, const StepParams& p,
                   const std::vector<vec4>& ref = {});

/// The state of the impulse stage (MOTES_FLAG_IMPULSE) that impulses_compute and impulses_apply
/// read or write besides the particles and bodies.
struct ImpulseState {
  std::vector<vec4> vel0;     ///< B: BodyVelStart (w: the body's counted contacts)
  std::vector<vec4> angvel0;  ///< B: BodyAngVelStart
  std::vector<vec4> acc;      ///< (K + P) x Nr: ContactImpulse, slot k of particle i at k Nr + i
  /// (K + P) x Nr: ContactImpulseSplit (the correcting sweeps of split impulses, filled by the
  /// last relaxing sweep: MOTES_FLAG_IMPULSE_SPLIT, MOTES_FLAG_IMPULSE_PUSH)
  std::vector<vec4> acc_split;
  std::vector<uint> stamp;        ///< Nr: ImpulseStamp
  uint builds = 0;                ///< NeighbourState[MOTES_NEIGHBOUR_BUILDS]
  std::vector<vec4> impulse;      ///< Nr: ParticleForce (xyz impulse, w counted contacts)
  std::vector<vec4> moment;       ///< Nr: ParticleMoment
  std::vector<vec4> vel_push;     ///< B: BodyVelPush (written with MOTES_FLAG_IMPULSE_PUSH)
  std::vector<vec4> angmom_push;  ///< B: BodyAngMomPush
};

/// impulses_compute: for every dynamic rigid particle i (static ones get 0), the contacts with the
/// rigid particles j of nb.lists[i] (every neighbour, in canonical order: what the device reads
/// from its list, or walks in the grid beyond K), each with shared::pair_impulse (lower id first)
/// and the accumulated impulse of i's slot k (shared::impulse_pair_slotted; an unslotted contact
/// starts from 0 and keeps nothing), then the planes (slot K + k) with plane_contact_impulse; the
/// counting pass reads a pair's slot only when shared::impulse_slots_valid (both particles'
/// stamps are builds, or the other is static). Summed in float in that order
/// (shared::impulse_add), as the contract says.
void impulses_compute(const Particles& particles, const Bodies& bodies, const Neighbours& nb,
                      const std::vector<ContactLaw>& laws, const std::vector<PlaneData>& planes,
                      const StepParams& p, ImpulseState& s);

/// impulses_apply: each dynamic body's particles' impulses, counts and moments summed in float in
/// chunks of MOTES_BODY_CHUNK particles from its first (each chunk in particle order from zero,
/// then the chunks' sums in order from zero: plain particle order for a body of up to 64); the
/// counting pass first keeps vel0 = (vel, count) and angvel0 = angvel (a position contacts'
/// counting pass after the first keeps their velocities: shared::impulse_start_velocity) and stamps
/// the dynamic bodies' particles with builds; then shared::body_apply_impulse (static bodies:
/// angvel from angmom only); with MOTES_FLAG_IMPULSE_PUSH, vel_push and angmom_push = what it
/// leaves. With MOTES_FLAG_POSITION_GRAM the sums are n n^T (shared::impulse_add), angvel0.w =
/// shared:: gram_bound of shared::gram_add over the body's particles in particle order (arms from
/// pos, the particles' positions), and nothing is applied.
void impulses_apply(Bodies& bodies, const StepParams& p, ImpulseState& s,
                    const std::vector<vec4>& pos = {});

/// What neighbours_build does to ImpulseStamp (impulse contacts): each rigid particle i whose
/// stamp is `built` (the last build's count) and whose new list `now` equals its old one
/// (old_list: the NeighbourList buffer before the build, entry k at k N + i; old_count: the
/// NeighbourCount before) by shared::neighbour_keeps_slots gets stamp built + 1; the others keep
/// theirs. Static particles (no list) keep theirs.
void impulse_stamps_after_build(const Particles& particles, const std::vector<uint>& old_list,
                                const std::vector<uint>& old_count, const Neighbours& now,
                                const StepParams& p, uint built, std::vector<uint>& stamp);

/// halo_pack: for each particle entry k < p.halo_particles, the particle i = index[p.halo_first +
/// k]: data[2k] = its position, data[2k + 1] = its velocity; then for each body entry j <
/// p.halo_bodies, the body b = index[p.halo_first + p.halo_particles + j]: data[2 P + 5 j + 0..4]
/// = its pos, quat, vel, angmom, angvel (shared/halo.h). An entry whose index is not below
/// p.particle_count (p.body_count) is skipped: `data` keeps what it held there.
void halo_pack(const Particles& particles, const Bodies& bodies, const std::vector<uint>& index,
               const StepParams& p, std::vector<vec4>& data);

/// halo_unpack: the reverse of halo_pack, the same entries (out of range: nothing written).
/// Returns whether a particle it wrote is too far from its `ref`
/// (shared::neighbour_moved_too_far).
bool halo_unpack(Particles& particles, Bodies& bodies, const std::vector<uint>& index,
                 const std::vector<vec4>& data, const StepParams& p, const std::vector<vec4>& ref);

/// particles_displacement: the largest shared::displacement2_bits(pos[i], ref[i]) over particles
/// [0, p.particle_count); 0 when there is none.
uint particles_displacement(const std::vector<vec4>& pos, const std::vector<vec4>& ref,
                            const StepParams& p);

/// One whole step in the core's order (the grid and the lists are skipped: the brute-force
/// contacts do not need them).
void step(Particles& particles, Bodies& bodies, const std::vector<ContactLaw>& laws,
          const std::vector<PlaneData>& planes, const StepParams& p);

/// fluid_density (docs/fluids.md): FluidState of the fluid particles [p.fluid_first, +
/// p.fluid_count): (rho_i, lambda_i, Lambda_i, 0), rho_i = m_i W(0) + sum over nb.lists[i] of
/// m_j W_ij (a solid j: psi_j = s rho_0 (2 r_j)^3) + rho_0 times each plane's share,
/// lambda_i = shared::fluid_lambda of the unilateral constraint with grad_i C_i and the
/// denominator gathered by shared::fluid_gradient_term (a solid's w 0) and the planes' slopes;
/// Lambda_i = lambda_i with MOTES_FLAG_POSITION_FIRST, else state's + lambda_i.
std::vector<vec4> fluid_density(const Particles& particles, const Neighbours& nb,
                                const std::vector<PlaneData>& planes,
                                const std::vector<motes::shared::FluidMaterial>& fluids,
                                const std::vector<vec4>& state, const StepParams& p);
/// fluid_update: ParticleForce of every particle: a fluid particle's (dx_i, 1), dx_i the sum
/// over nb.lists[i] of shared::fluid_shift_term (lambda from state's y; a solid j: lambda_j 0,
/// s_corr 0, m_j = psi_j) then each plane's slope times lambda_i w_i along its normal; every
/// other particle's 0.
std::vector<vec4> fluid_update(const Particles& particles, const Neighbours& nb,
                               const std::vector<PlaneData>& planes,
                               const std::vector<motes::shared::FluidMaterial>& fluids,
                               const std::vector<vec4>& state, const StepParams& p);

/// What fluid_vorticity writes, one vec4 per fluid particle each.
struct FluidVorticity {
  std::vector<vec4> vel_old;  ///< FluidVelOld: (v_i, 0)
  std::vector<vec4> aux;      ///< FluidAux: (omega_i, |omega_i|)
  std::vector<vec4> normal;   ///< FluidNormal: (n_i, 0)
};
/// fluid_vorticity: for every fluid particle, over the fluid particles of nb.lists[i] in order
/// (solids skipped), omega_i = sum of shared::fluid_vorticity_term and n_i = sum of
/// shared::fluid_normal_term (m_j its material's mass, rho_j state's x, h i's material's).
FluidVorticity fluid_vorticity(const Particles& particles, const Neighbours& nb,
                               const std::vector<motes::shared::FluidMaterial>& fluids,
                               const std::vector<vec4>& state, const StepParams& p);
/// fluid_velocity: ParticleVel of every particle: a fluid particle's (v_i + dv_i, its w), v_i
/// and its neighbours' velocities from `vort`.vel_old, dv_i = ((c xsph + shared::
/// fluid_confinement(eta, omega_i, eps, h_s)) + cohesion) + adhesion, the sums over nb.lists[i]
/// in order: a fluid j with r^2 <= h^2 adds shared::fluid_xsph_term, fluid_eta_term and
/// fluid_cohesion_term, a solid j fluid_adhesion_term (psi_j = s rho_0 (2 r_j)^3); every other
/// particle's velocity as it was. With MOTES_FLAG_FLUID_ADHESION every solid particle b with
/// w_b != 0 sums shared::fluid_adhesion_reaction over the fluid particles of nb.lists[b] in order:
/// a rigid one's (b < rigid_particle_count) becomes (*force)[b] = (R, 0) (a static rigid one's
/// (0, 0)), a free one's velocity shared::fluid_adhesion_taken; `force` may be null without it.
std::vector<vec4> fluid_velocity(const Particles& particles, const Neighbours& nb,
                                 const std::vector<motes::shared::FluidMaterial>& fluids,
                                 const std::vector<vec4>& state, const FluidVorticity& vort,
                                 const StepParams& p, std::vector<vec4>* force = nullptr);

}  // namespace motes_ref
