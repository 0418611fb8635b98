// Every kernel family, named once (docs/architecture.md, "Adding a kernel family"). A family is
// one name: the Kernel enumerator, the name in timings, tables and conformance filters, the file
// of each backend (backends/openmp/NAME.cpp, backends/cuda/NAME.cu, backends/vulkan/NAME.cpp with
// shaders/NAME*.comp), its oracle (tests/reference/NAME.cpp) and its conformance file
// (tests/conformance/test_NAME.cpp). The list below gives, in the order a step runs them, each
// family's enumerator, its name, and the buffers it reads and writes (motes::Buffer enumerators;
// a buffer a family changes only in part, keeping the rest, is in both). The conformance suite
// checks both lists on every backend: it poisons every buffer a call neither reads nor writes
// and requires every buffer outside its writes unchanged afterwards.
//
// The contracts (what each family computes; the same on every backend):
//
// neighbours_update: when NeighbourState[MOTES_NEIGHBOUR_REBUILD] is nonzero, grid_build then
//   neighbours_build (each timed as itself); otherwise nothing. Decided on the device, so that a
//   queued step needs no host round trip.
// grid_build: buckets, a stable sort by (bucket, particle id), bucket starts, sorted copies of
//   the particles.
// neighbours_build: from the grid, every dynamic particle's list of the particles of other
//   bodies closer than r_i + r_j + skin (shared/neighbours.h), in the canonical order of the
//   27-cell walk, its first K entries kept and its full count written (static particles: 0);
//   NeighbourRefPos = ParticlePos; NeighbourState: rebuild 0, builds + 1, the particles over
//   capacity and the largest count; with impulse contacts, ImpulseStamp of every rigid particle.
// contacts_compute: ParticleForce: each dynamic particle sums the contact forces of its list in
//   order (a particle with more than K neighbours walks the grid of the last build from the cell
//   of its NeighbourRefPos instead: the same pairs in the same order), then the planes in order.
//   Static particles get 0. Exact while no particle has moved 0.45 skin since the build.
// bodies_reduce: BodyForce and BodyTorque: sums over each body's particles in particle order.
// bodies_integrate: semi-implicit Euler on every dynamic body (shared/body_math.h:
//   body_integrate; with impulse contacts from BodyVelPush and BodyAngMomPush, or with
//   MOTES_FLAG_IMPULSE_SPLIT from BodyVel and BodyAngMom, which then take the push copies:
//   body_split_pose, both moving the centre as the pair BodyPos + BodyPosLow; with position
//   contacts, MOTES_FLAG_POSITION, the prediction with gravity alone).
// particles_update: ParticlePos and ParticleVel xyz of the rigid particles [0, Nr) from their
//   body's pose; asks for a rebuild (NeighbourState) when one has moved too far from its
//   NeighbourRefPos. With MOTES_FLAG_ABSORB, first ParticleForce =
//   shared::particle_absorbed_impulse of the particle's velocity as it is and ParticleMoment =
//   (R local) x that impulse.
// particles_integrate: semi-implicit Euler on the free particles [Nr, N)
//   (shared/body_math.h: particle_integrate), the velocities of the linked particles [Nl, N)
//   first multiplied by 1 - p.linked_damping; asks for a rebuild when one has moved too far.
// clusters_fit: ClusterFrames: for each of the p.cluster_count clusters, the centre of mass of
//   its members and A_pq (cluster_centre_add, cluster_moment_add), summed in member order, then
//   shared/shape_matching.h: cluster_frame, from the cluster's last rotation.
// clusters_goal: every soft particle [p.soft_first, p.linked_first) moved by the sum of
//   cluster_shift over its members in ClusterGather order (its velocity by the same / dt); asks
//   for a rebuild when one ends too far from its NeighbourRefPos.
// constraints_solve: one colour of distance constraints: Constraints [p.constraint_first,
//   + p.constraint_count), no two of which share a particle, each projected once
//   (shared/links.h: constraint_correction) on ParticlePos and ParticleVel; asks for a rebuild
//   when a particle it moved is too far from its NeighbourRefPos.
// constraints_relax: every sweep of every colour in one launch, for sets small enough for one
//   workgroup: p.constraint_sweeps sweeps, each over the p.constraint_count colours in order,
//   colour k being Constraints [ConstraintColours[k], ConstraintColours[k + 1]); each colour
//   exactly as constraints_solve, one after the other, so the result is that of
//   p.constraint_sweeps x p.constraint_count constraints_solve calls, bit for bit. With
//   MOTES_FLAG_SKIN_CHECK only the last sweep asks for a rebuild (as the core flags the last
//   sweep's constraints_solve calls).
// impulses_compute: impulse contacts (shared/impulse.h), rigid particles [0, Nr) only:
//   ParticleForce xyz = the sum of pair_impulse over its list's rigid particles in list order
//   (each pair evaluated lower id first, negated for the higher; the particles as
//   contact_particle gives them: R ParticleLocal, or ParticlePos for position contacts), then
//   plane_contact_impulse over the planes; w = the contacts counted; ParticleMoment = the sum of
//   (c - x_com) x J; the contacts' accumulated impulses in ContactImpulse (ImpulseStamp says
//   which are valid; with MOTES_FLAG_IMPULSE_SPLIT in ContactImpulseSplit instead, and with
//   MOTES_FLAG_IMPULSE_PUSH written to both). Static particles get 0. With MOTES_FLAG_IMPULSE_COUNT
//   the same (only w is used). A sweep (no MOTES_FLAG_IMPULSE_COUNT) after its substep's counting
//   pass, positions and lists unchanged since, may visit only the particles that pass found within
//   reach of a contact (the others' impulses are 0, as the step needs); a backend that keeps that
//   must forget it at allocate and at a write of positions or lists. With MOTES_FLAG_POSITION the
//   contacts are position contacts (shared/position.h: contact_position; ContactImpulse slots
//   zeroed): the counting pass, the projection, or (MOTES_FLAG_POSITION_VELOCITY) the velocity
//   pass, which may follow a projection that moved the poses.
// impulses_apply: every dynamic body sums its particles' ParticleForce and ParticleMoment in
//   chunks of 64 particles (each in particle order, then the chunks in order: shared/impulse.h,
//   MOTES_BODY_CHUNK), then shared/impulse.h: body_apply_impulse (BodyVel, BodyAngMom, BodyAngVel).
//   With MOTES_FLAG_IMPULSE_COUNT instead: BodyVelStart = (BodyVel xyz, the summed count),
//   BodyAngVelStart = BodyAngVel; with MOTES_FLAG_IMPULSE_PUSH the pushed velocities. With
//   MOTES_FLAG_POSITION alone (the projection of position contacts), shared/impulse.h:
//   body_apply_contacts moves BodyPos and BodyQuat too (shared/position.h). With
//   MOTES_FLAG_POSITION_GRAM (a counting pass) the sums are each particle's n n^T, and
//   BodyAngVelStart.w gets the body's contact Gram bound from them and ParticlePos
//   (shared/contact_gram.h); nothing is applied.
// fluid_density (docs/fluids.md; shared/fluid.h): every fluid particle [p.fluid_first,
//   + p.fluid_count) gathers over its list in list order (over capacity: the 27 cells of the last
//   build from its NeighbourRefPos, whose particles beyond h add zeros), then over the planes:
//   rho_i = m_i W(0) + sum_j m_j W_ij (a solid j counts psi_j = s rho_0 (2 r_j)^3) + rho_0 times
//   each plane's share (fluid_plane_density), and lambda_i = fluid_lambda of the unilateral
//   constraint with grad_i C_i and the denominator (fluid_gradient_term; a solid's w 0; the
//   planes' slopes in grad_i C_i) and alpha~; FluidState[i - Nf] = (rho_i, lambda_i, Lambda_i, 0),
//   Lambda_i = lambda_i with MOTES_FLAG_POSITION_FIRST, else the old Lambda_i + lambda_i.
// fluid_update: ParticleForce of every particle: a fluid particle's (dx_i, 1), dx_i the sum over
//   the same neighbours in the same order of fluid_shift_term (lambda_j from FluidState; a solid
//   j: lambda_j 0, s_corr 0, m_j = psi_j), then each plane's slope along its normal times
//   lambda_i w_i; a solid particle that can move (w != 0), the sum over its fluid neighbours in
//   the same walk of fluid_solid_reaction, written by fluid_solid_force (a rigid particle's
//   momentum, w 0, for its body; a free particle's shift, w 1); a static particle's 0.
// fluid_vorticity (once a substep, after the positions): every fluid particle gathers over its
//   fluid neighbours (fluid_particle; solids skipped) in list order (over capacity: the 27 cells
//   of the last build, whose particles beyond h add zeros), with m_j its material's mass, rho_j
//   FluidState's and i's h: FluidVelOld[i - Nf] = (v_i, 0); FluidAux[i - Nf] = (omega_i,
//   |omega_i|), omega_i = sum_j fluid_vorticity_term; FluidNormal[i - Nf] = (n_i, 0),
//   n_i = sum_j fluid_normal_term.
// fluid_velocity: every fluid particle, from FluidVelOld (its own and its neighbours' velocities;
//   never ParticleVel, which it writes), FluidAux, FluidNormal and FluidState, gathers over the
//   same neighbours in the same order, in one loop: for a fluid j within h (r^2 <= h^2), the XSPH
//   sum of fluid_xsph_term, eta_i of fluid_eta_term and the cohesion sum of
//   fluid_cohesion_term; for a solid j, the adhesion sum of fluid_adhesion_term (psi_j of
//   fluid_neighbour_mass); ParticleVel[i].xyz = v_i + (((c xsph + fluid_confinement(eta_i,
//   omega_i, eps, h_s)) + cohesion) + adhesion) with i's material's (c, eps, gamma, beta) and
//   h_s = p.gravity_dt.w, w kept; every other particle untouched. With MOTES_FLAG_FLUID_ADHESION
//   every solid particle b too (items [0, particle_count)): with w_b != 0 it sums
//   fluid_adhesion_reaction over its fluid neighbours in the same order (else 0); a rigid one
//   (b < rigid_particle_count) writes ParticleForce[b] = (R, 0), a free one ParticleVel[b] =
//   fluid_adhesion_taken(v_b, R); every other ParticleForce untouched.
// particles_check (not part of a step: the motion guard): MotionCheck gets the largest
//   (|v| / d)^2 of a finite particle of [0, particle_count), the first particle with it and its
//   |v|^2, and the first particle whose position or velocity is not finite
//   (shared/motion_check.h).
// energy_reduce (not part of a step: the energy guard, shared/energy.h): for every block of
//   MOTES_ENERGY_BLOCK items (the rigid bodies [0, p.body_count), then the particles
//   [p.rigid_particle_count, p.particle_count)), EnergyPartials gets the sum of its items'
//   shared::item_energy (from the reference point in EnergyPartials' header) added as a tree in
//   the fixed order of shared/energy.h, its largest item kinetic energy and the lowest item with
//   it; the header is left as it is.
// halo_pack (runs over MPI ranks, shared/halo.h, docs/scale-out.md): HaloData = the state of the
//   p.halo_particles particles at HaloIndex [p.halo_first, + p.halo_particles) (entry k:
//   ParticlePos at 2k, ParticleVel at 2k + 1), then of the p.halo_bodies rigid bodies at the
//   next p.halo_bodies words (entry j at 2 P + 5 j: BodyPos, BodyQuat, BodyVel, BodyAngMom,
//   BodyAngVel). Plain copies: the same bits on every backend. An entry whose index is not below
//   p.particle_count (a particle) or p.body_count (a body) is skipped.
// halo_unpack: the reverse of halo_pack with the same layout; asks for a rebuild when a particle
//   it wrote is too far from its NeighbourRefPos, and leaves NeighbourState as it is otherwise.
// particles_displacement: PartitionCheck[0] = the largest of shared/halo.h:
//   displacement2_bits(ParticlePos[i], PartitionRefPos[i]) over [0, p.particle_count).
#pragma once

// X(Enumerator, name, (buffers read), (buffers written)), in the order a step runs them.
#define MOTES_KERNELS(X)                                                                         \
  X(NeighboursUpdate, neighbours_update,                                                         \
    (ParticlePos, ParticleVel, ParticleBody, NeighbourState, LinkExclusions, ImpulseStamp),      \
    (GridBucket, GridOrder, GridCellStart, SortedPos, SortedBody, NeighbourList, NeighbourCount, \
     NeighbourRefPos, NeighbourState, ImpulseStamp))                                             \
  X(GridBuild, grid_build, (ParticlePos, ParticleBody),                                          \
    (GridBucket, GridOrder, GridCellStart, SortedPos, SortedBody))                               \
  X(NeighboursBuild, neighbours_build,                                                           \
    (ParticlePos, ParticleVel, ParticleBody, GridOrder, GridCellStart, SortedPos, SortedBody,    \
     NeighbourState, LinkExclusions, ImpulseStamp),                                              \
    (NeighbourList, NeighbourCount, NeighbourRefPos, NeighbourState, ImpulseStamp))              \
  X(ContactsCompute, contacts_compute,                                                           \
    (ParticlePos, ParticleVel, ParticleBody, ParticleMaterial, GridOrder, GridCellStart,         \
     SortedPos, SortedBody, NeighbourList, NeighbourCount, NeighbourRefPos, ContactLaws, Planes, \
     LinkExclusions),                                                                            \
    (ParticleForce))                                                                             \
  X(BodiesReduce, bodies_reduce, (ParticlePos, ParticleForce, BodyPos, BodyFirst),               \
    (BodyForce, BodyTorque))                                                                     \
  X(BodiesIntegrate, bodies_integrate,                                                           \
    (BodyPos, BodyQuat, BodyVel, BodyAngMom, BodyAngVel, BodyInvInertia, BodyForce, BodyTorque,  \
     BodyVelPush, BodyAngMomPush, BodyPosLow),                                                   \
    (BodyPos, BodyQuat, BodyVel, BodyAngMom, BodyAngVel, BodyPosLow))                            \
  X(ParticlesUpdate, particles_update,                                                           \
    (ParticlePos, ParticleVel, ParticleForce, ParticleLocal, ParticleBody, BodyPos, BodyQuat,    \
     BodyVel, BodyAngVel, NeighbourRefPos, NeighbourState),                                      \
    (ParticlePos, ParticleVel, ParticleForce, ParticleMoment, NeighbourState))                   \
  X(ParticlesIntegrate, particles_integrate,                                                     \
    (ParticlePos, ParticleVel, ParticleForce, NeighbourRefPos, NeighbourState),                  \
    (ParticlePos, ParticleVel, NeighbourState))                                                  \
  X(ClustersFit, clusters_fit,                                                                   \
    (ParticlePos, ParticleVel, Clusters, ClusterMembers, ClusterFrames), (ClusterFrames))        \
  X(ClustersGoal, clusters_goal,                                                                 \
    (ParticlePos, ParticleVel, NeighbourRefPos, NeighbourState, ClusterMembers, ClusterFrames,   \
     ClusterGather),                                                                             \
    (ParticlePos, ParticleVel, NeighbourState))                                                  \
  X(ConstraintsSolve, constraints_solve,                                                         \
    (ParticlePos, ParticleVel, NeighbourRefPos, NeighbourState, Constraints),                    \
    (ParticlePos, ParticleVel, NeighbourState))                                                  \
  X(ConstraintsRelax, constraints_relax,                                                         \
    (ParticlePos, ParticleVel, NeighbourRefPos, NeighbourState, Constraints, ConstraintColours), \
    (ParticlePos, ParticleVel, NeighbourState))                                                  \
  X(ImpulsesCompute, impulses_compute,                                                           \
    (ParticlePos, ParticleVel, ParticleLocal, ParticleBody, ParticleMaterial, BodyPos, BodyQuat, \
     BodyVel, BodyAngVel, BodyInvInertia, BodyFirst, GridOrder, GridCellStart, SortedPos,        \
     SortedBody, NeighbourList, NeighbourCount, NeighbourRefPos, NeighbourState, ContactLaws,    \
     Planes, BodyVelStart, BodyAngVelStart, ContactImpulse, ImpulseStamp, ContactImpulseSplit),  \
    (ParticleForce, ParticleMoment, ContactImpulse, ImpulseStamp, ContactImpulseSplit))          \
  X(ImpulsesApply, impulses_apply,                                                               \
    (ParticleForce, ParticleMoment, BodyPos, BodyQuat, BodyVel, BodyAngMom, BodyAngVel,          \
     BodyInvInertia, BodyFirst, BodyVelStart, BodyAngVelStart, NeighbourState, ImpulseStamp,     \
     BodyVelPush, BodyAngMomPush, ParticlePos),                                                  \
    (BodyPos, BodyQuat, BodyVel, BodyAngMom, BodyAngVel, BodyVelStart, BodyAngVelStart,          \
     ImpulseStamp, BodyVelPush, BodyAngMomPush))                                                 \
  X(FluidDensity, fluid_density,                                                                 \
    (ParticlePos, ParticleVel, ParticleBody, ParticleMaterial, GridOrder, GridCellStart,         \
     SortedBody, NeighbourList, NeighbourCount, NeighbourRefPos, Planes, LinkExclusions,         \
     FluidMaterials, FluidState),                                                                \
    (FluidState))                                                                                \
  X(FluidUpdate, fluid_update,                                                                   \
    (ParticlePos, ParticleVel, ParticleBody, ParticleMaterial, GridOrder, GridCellStart,         \
     SortedBody, NeighbourList, NeighbourCount, NeighbourRefPos, Planes, LinkExclusions,         \
     FluidMaterials, FluidState),                                                                \
    (ParticleForce))                                                                             \
  X(FluidVorticity, fluid_vorticity,                                                             \
    (ParticlePos, ParticleVel, ParticleBody, ParticleMaterial, GridOrder, GridCellStart,         \
     SortedBody, NeighbourList, NeighbourCount, NeighbourRefPos, LinkExclusions, FluidMaterials, \
     FluidState),                                                                                \
    (FluidVelOld, FluidAux, FluidNormal))                                                        \
  X(FluidVelocity, fluid_velocity,                                                               \
    (ParticlePos, ParticleVel, ParticleBody, ParticleMaterial, GridOrder, GridCellStart,         \
     SortedBody, NeighbourList, NeighbourCount, NeighbourRefPos, LinkExclusions, FluidMaterials, \
     FluidState, FluidVelOld, FluidAux, FluidNormal),                                            \
    (ParticleVel, ParticleForce))                                                                \
  X(ParticlesCheck, particles_check, (ParticlePos, ParticleVel), (MotionCheck))                  \
  X(EnergyReduce, energy_reduce,                                                                 \
    (ParticlePos, ParticleVel, BodyPos, BodyVel, BodyAngMom, BodyAngVel, EnergyPartials),        \
    (EnergyPartials))                                                                            \
  X(HaloPack, halo_pack,                                                                         \
    (ParticlePos, ParticleVel, BodyPos, BodyQuat, BodyVel, BodyAngMom, BodyAngVel, HaloIndex,    \
     HaloData),                                                                                  \
    (HaloData))                                                                                  \
  X(HaloUnpack, halo_unpack,                                                                     \
    (ParticlePos, ParticleVel, BodyPos, BodyQuat, BodyVel, BodyAngMom, BodyAngVel,               \
     NeighbourRefPos, NeighbourState, HaloIndex, HaloData),                                      \
    (ParticlePos, ParticleVel, BodyPos, BodyQuat, BodyVel, BodyAngMom, BodyAngVel,               \
     NeighbourState))                                                                            \
  X(ParticlesDisplacement, particles_displacement, (ParticlePos, PartitionRefPos), (PartitionCheck))
