// motes::Simulation: turns a Scene into device buffers and runs the step pipeline.
#include "motes/simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>

#include "motes/backend/env.h"
#include "motes/checkpoint.h"
#include "scene_layout.h"
#include "shared/body_math.h"
#include "shared/energy.h"
#include "shared/halo.h"
#include "shared/neighbours.h"

namespace motes {

using shared::vec4;

namespace {

using layout::to_vec4;

template <typename T>
Status write_vector(Device& d, Buffer b, const std::vector<T>& v) {
  return d.write(b, v.data(), v.size() * sizeof(T));
}

template <typename T>
Status read_vector(Device& d, Buffer b, std::vector<T>& v, std::size_t count) {
  v.resize(count);
  return d.read(b, v.data(), count * sizeof(T));
}

/// Writes the layout's buffers (after allocating them all), in one loop.
Status write_layout(Device& d, const layout::HostLayout& host) {
  struct Upload {
    Buffer buffer;
    const void* data;
    std::size_t bytes;
  };
  const auto of = [](Buffer b, const auto& v) {
    return Upload{b, v.data(), v.size() * sizeof(v[0])};
  };
  const layout::ParticleLayout& p = host.particles;
  const layout::RigidLayout& r = host.rigid;
  const std::uint32_t neighbour_state[4] = {1u, 0u, 0u, 0u};  // build at the first step
  std::vector<Upload> uploads = {
      of(Buffer::ParticlePos, p.pos),
      of(Buffer::ParticleVel, p.vel),
      of(Buffer::ParticleLocal, r.local),
      of(Buffer::ParticleBody, p.body),
      of(Buffer::ParticleMaterial, p.material),
      of(Buffer::BodyPos, r.pos),
      of(Buffer::BodyQuat, r.quat),
      of(Buffer::BodyVel, r.vel),
      of(Buffer::BodyAngMom, r.angmom),
      of(Buffer::BodyAngVel, r.angvel),
      of(Buffer::BodyInvInertia, r.inv_inertia),
      of(Buffer::BodyFirst, r.first),
      of(Buffer::NeighbourRefPos, p.pos),
      {Buffer::NeighbourState, neighbour_state, sizeof neighbour_state},
      of(Buffer::ContactLaws, host.tables.laws),
      of(Buffer::Planes, host.tables.planes),
      of(Buffer::Constraints, host.linked.colouring.constraints),
      of(Buffer::Clusters, host.soft.clusters.clusters),
      of(Buffer::ClusterMembers, host.soft.clusters.members),
      of(Buffer::ClusterFrames, host.soft.frames),
      of(Buffer::ClusterGather, host.soft.gather),
      of(Buffer::LinkExclusions, host.linked.exclusions),
      of(Buffer::HaloIndex, host.halo.index),
      of(Buffer::FluidMaterials, host.fluid_materials),
  };
  // A rank of a run over MPI ranks: the partition's reference positions.
  if (host.sizes.partition != 0) uploads.push_back(of(Buffer::PartitionRefPos, p.pos));
  if (host.sizes.constraints != 0) {
    uploads.push_back(of(Buffer::ConstraintColours, host.linked.colouring.first));
  }
  // Impulse contacts: every centre of mass starts as its float (nothing below it).
  const std::vector<vec4> low(host.sizes.impulse != 0 ? r.pos.size() : 0, vec4(0.0f));
  if (!low.empty()) uploads.push_back(of(Buffer::BodyPosLow, low));
  Status s = d.allocate(host.sizes);
  for (const Upload& u : uploads) {
    if (!s) break;
    s = d.write(u.buffer, u.data, u.bytes);
  }
  return s;
}

/// Host memory for `count` vec4s of the packed halo, freed through the device (none for 0).
Status allocate_halo(Device& d, std::size_t count, HostMemory<vec4>& memory) {
  memory = HostMemory<vec4>(
      count == 0 ? nullptr : static_cast<vec4*>(d.allocate_host(count * sizeof(vec4))),
      HostFree{&d});
  if (count > 0 && !memory) {
    return Status::error(
        fmt::format("no host memory for a halo of {} bytes", count * sizeof(vec4)));
  }
  return Status::ok();
}

/// The point lowest along gravity (the first of equals; the first without gravity) of the
/// particles and the emitters' nozzles, leaving out the emitters' parked particles.
vec4 lowest_point(const Eigen::Vector3d& gravity, const std::vector<vec4>& pos,
                  const std::vector<EmitterRange>& emitters) {
  const auto g_dot = [&](const vec4& x) {
    return gravity.dot(Eigen::Vector3f(x.x, x.y, x.z).cast<double>());
  };
  // The candidates in order, without a copy: the nozzles, then the particles not parked (the
  // emitters' ranges are disjoint, so a particle is parked when it lies in one of them).
  const auto parked = [&](std::size_t i) {
    return std::any_of(emitters.begin(), emitters.end(), [i](const EmitterRange& e) {
      return i >= e.first && i - e.first < e.count;
    });
  };
  std::optional<vec4> lowest;
  const auto consider = [&](const vec4& x) {
    if (!lowest || g_dot(x) > g_dot(*lowest)) lowest = x;
  };
  for (const EmitterRange& e : emitters) consider(to_vec4(e.emitter.position, 0.0));
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (emitters.empty() || !parked(i)) consider(pos[i]);
  }
  return lowest.value_or(vec4(0.0f));
}

/// The most constraints relaxed in one launch (constraints_relax): the device's
/// DeviceInfo::one_launch_constraints, or MOTES_CONSTRAINTS_RELAX_LIMIT=C (0: always a launch per
/// colour; benchmarks and tests compare the two ways); an error when C is not a whole number.
Result<std::uint64_t> constraints_relax_limit(const Device& device) {
  Result<std::optional<std::uint64_t>> limit = env_whole_number(
      "MOTES_CONSTRAINTS_RELAX_LIMIT",
      "a number of constraints (a whole number; 0 relaxes them a launch per colour)");
  if (!limit) return limit.status();
  return limit.value().value_or(device.info().one_launch_constraints);
}

}  // namespace

Result<std::unique_ptr<Simulation>> Simulation::create(const Scene& scene,
                                                       std::unique_ptr<Device> device) {
  if (!device) return Status::error("Simulation::create: no device");
  std::unique_ptr<Simulation> sim(new Simulation());
  sim->device_ = std::move(device);
  if (Status s = sim->upload(scene, nullptr); !s) return s;
  return sim;
}

Result<std::unique_ptr<Simulation>> Simulation::create(const Scene& scene,
                                                       std::unique_ptr<Device> device,
                                                       const HaloLists& halo) {
  if (!device) return Status::error("Simulation::create: no device");
  std::unique_ptr<Simulation> sim(new Simulation());
  sim->device_ = std::move(device);
  if (Status s = sim->upload(scene, &halo); !s) return s;
  return sim;
}

std::unique_ptr<Device> Simulation::take_device(std::unique_ptr<Simulation> sim) {
  if (!sim) return nullptr;
  (void)sim->device_->synchronize();
  sim->halo_out_.reset();  // freed through the device, before it goes
  sim->halo_in_.reset();
  return std::move(sim->device_);
}

Status Simulation::upload(const Scene& scene, const HaloLists* halo) {
  settings_ = scene.settings;
  // Count first, so an impossible size is refused before anything is allocated.
  SceneBodies order = scene_bodies(scene);
  Result<layout::SceneCounts> counted = layout::count_scene(scene, order, halo);
  if (!counted) return counted.status();
  const layout::SceneCounts& counts = counted.value();
  layout::HostLayout host;
  host.sizes = layout::count_sizes(scene, counts, halo);
  Device& d = *device_;
  // Device memory and buffer limits: refuse before allocating anything, with both numbers and the
  // largest particle count that fits (again once the clusters are known, before the device
  // allocates).
  const auto check_memory = [&]() -> Status {
    if (Status st = check_device_fits(d, host.sizes); !st) {
      return Status::error(fmt::format("{}: {}", scene.source, st.message()));
    }
    return Status::ok();
  };
  if (Status st = check_memory(); !st) return st;
  // Every family a run may call (the step's, the guards', the halo's) must be one the device runs.
  for (std::size_t k = 0; k < kKernelCount; ++k) {
    if (!d.supports(static_cast<Kernel>(k))) {
      return Status::error(fmt::format("{}: the {} device does not run the kernel family {}",
                                       scene.source, d.info().backend,
                                       kernel_name(static_cast<Kernel>(k))));
    }
  }

  // The host's layout, kind by kind (scene_layout.h).
  host.bodies = std::move(order.bodies);
  if (Status st = layout::build_bodies(scene, counts, host); !st) return st;
  if (Status st = layout::build_linked(scene, counts, host); !st) return st;
  if (Status st = layout::build_fluids(scene, counts, host); !st) return st;
  host.tables = layout::build_tables(scene);
  host.params = layout::build_params(settings_, counts, host);
  if (halo != nullptr) {
    if (Status st = layout::build_halo(scene.source, *halo, host); !st) return st;
    // The packed halo's host memory, sent and received.
    halo_entries_ = host.halo.entries;
    halo_out_count_ = std::size_t{MOTES_HALO_PARTICLE_VEC4S} * halo_entries_[0] +
                      std::size_t{MOTES_HALO_BODY_VEC4S} * halo_entries_[1];
    halo_in_count_ = std::size_t{MOTES_HALO_PARTICLE_VEC4S} * halo_entries_[2] +
                     std::size_t{MOTES_HALO_BODY_VEC4S} * halo_entries_[3];
    for (auto [memory, count] :
         {std::pair{&halo_out_, halo_out_count_}, std::pair{&halo_in_, halo_in_count_}}) {
      if (Status st = allocate_halo(d, count, *memory); !st) {
        return Status::error(fmt::format("{}: {}", scene.source, st.message()));
      }
    }
  }
  if (Status st = check_memory(); !st) return st;

  // What the host keeps of the layout, and the setup's fingerprint (scene_layout.h).
  const layout::Fingerprint fingerprint = layout::fingerprint(settings_, host);
  setup_hash_ = fingerprint.setup;
  particle_w_hash_ = fingerprint.particle_w;
  sizes_ = host.sizes;
  params_ = host.params;
  bodies_ = std::move(host.bodies);
  device_index_ = std::move(host.device_index);
  rigid_first_ = host.rigid.first;
  rigid_inv_inertia_ = host.rigid.inv_inertia;
  colour_first_ = host.linked.colouring.first;
  Result<std::uint64_t> relax_limit = constraints_relax_limit(d);
  if (!relax_limit) return relax_limit.status();
  relax_limit_ = relax_limit.value();
  sphere_turns_ = std::move(host.sphere_turns);
  emitters_ = host.emitters;

  Status s = write_layout(d, host);
  if (s) s = clear_contact_history();
  if (!s) return s;
  // The energy guard: the scene's model, and the reference point potential energy is measured
  // from, the lowest particle along gravity (the first without gravity), so that the device's
  // float energies stay precise wherever the scene is.
  energy_model_ = motes::energy_model(scene);
  rigid_scene_body_.assign(sizes_.bodies, 0u);
  position_bodies_ = std::any_of(bodies_.begin(), bodies_.end(), [](const BodyInfo& b) {
    return b.kind == BodyKind::Dynamic && b.has_body_state();
  });
  fluid_adhesion_ =
      std::any_of(host.fluid_materials.begin(), host.fluid_materials.end(),
                  [](const shared::FluidMaterial& f) { return f.velocity.w != 0.0f; });
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    if (bodies_[b].has_body_state())
      rigid_scene_body_[device_index_[b]] = static_cast<std::uint32_t>(b);
  }
  const std::vector<vec4>& ppos = host.particles.pos;
  const vec4 origin = lowest_point(settings_.gravity, ppos, emitters_);
  energy_origin_ = Eigen::Vector3f(origin.x, origin.y, origin.z).cast<double>();
  const std::uint32_t header[MOTES_ENERGY_HEADER] = {
      shared::float_bits(origin.x), shared::float_bits(origin.y), shared::float_bits(origin.z), 0u};
  if (Status st = d.write(Buffer::EnergyPartials, header, sizeof header); !st) return st;
  energy_started_ = false;
  // Rigid particles take their pose from the bodies with the device's own arithmetic.
  if (sizes_.rigid_particles > 0) d.enqueue(Kernel::ParticlesUpdate, params_);
  return d.synchronize();
}

Status Simulation::step(std::uint64_t count) {
  Device& d = *device_;
  const bool rigid = sizes_.bodies > 0;
  const bool free = sizes_.particles > sizes_.rigid_particles;
  // A list build moves the impulse contacts' memory on (ImpulseStamp) only when the setting asks.
  shared::StepParams lists = params_;
  if (!settings_.impulse_memory_across_builds) lists.flags &= ~MOTES_FLAG_IMPULSE;
  const bool positions = settings_.contact_model == ContactModel::Positions;
  for (std::uint64_t k = 0; k < count; ++k) {
    if (!emitters_.empty()) {
      if (Status s = emit(); !s) return s;
    }
    if (positions) step_positions(lists);
    for (int sub = 0; sub < settings_.substeps && !positions; ++sub) {
      d.enqueue(Kernel::NeighboursUpdate, lists);
      d.enqueue(Kernel::ContactsCompute, params_);
      if (rigid && sizes_.impulse != 0) {
        step_impulses();
      } else if (rigid) {
        d.enqueue(Kernel::BodiesReduce, params_);
        d.enqueue(Kernel::BodiesIntegrate, params_);
        d.enqueue(Kernel::ParticlesUpdate, params_);
      }
      if (free) d.enqueue(Kernel::ParticlesIntegrate, params_);
      if (params_.cluster_count > 0) {
        d.enqueue(Kernel::ClustersFit, params_);
        d.enqueue(Kernel::ClustersGoal, params_);
      }
      relax_constraints();
      if (sizes_.absorb != 0) absorb_attachments();
    }
    ++steps_;
    time_ = static_cast<double>(steps_) * settings_.dt;
  }
  return d.synchronize();
}

void Simulation::relax_constraints() {
  // settings.constraint_iterations sweeps over the colours of the cloth and rope constraints
  // (docs/architecture.md, "Cloth and ropes"): all in one launch when they are few, else one
  // launch per colour. Both give the same bits.
  if (colour_first_.size() < 2 || settings_.constraint_iterations < 1) return;
  if (colour_first_.back() <= relax_limit_) {
    shared::StepParams all = params_;
    all.flags |= MOTES_FLAG_SKIN_CHECK;  // in the last sweep
    all.constraint_first = 0;
    all.constraint_count = static_cast<std::uint32_t>(colour_first_.size() - 1);
    all.constraint_sweeps = static_cast<std::uint32_t>(settings_.constraint_iterations);
    device_->enqueue(Kernel::ConstraintsRelax, all);
    return;
  }
  for (int it = 0; it < settings_.constraint_iterations; ++it) {
    for (std::size_t c = 0; c + 1 < colour_first_.size(); ++c) {
      shared::StepParams colour = params_;
      // Only the last sweep's positions are the ones the next contacts see.
      if (it + 1 == settings_.constraint_iterations) colour.flags |= MOTES_FLAG_SKIN_CHECK;
      colour.constraint_first = colour_first_[c];
      colour.constraint_count = colour_first_[c + 1] - colour_first_[c];
      device_->enqueue(Kernel::ConstraintsSolve, colour);
    }
  }
}

void Simulation::absorb_attachments() {
  // Cloth and ropes attached to rigid bodies: the constraints moved the bodies' particles too; each
  // body takes what they did as an impulse (shared/body_math.h: particle_absorbed_impulse), summed
  // over its particles in order (impulses_apply), and its particles follow its pose again.
  Device& d = *device_;
  shared::StepParams absorb = params_;
  absorb.flags = (absorb.flags | MOTES_FLAG_ABSORB) & ~MOTES_FLAG_IMPULSE_COUNT;
  shared::StepParams apply = params_;
  apply.flags = (apply.flags | MOTES_FLAG_ABSORB) & ~MOTES_FLAG_IMPULSE_COUNT;
  d.enqueue(Kernel::ParticlesUpdate, absorb);
  d.enqueue(Kernel::ImpulsesApply, apply);
  d.enqueue(Kernel::ParticlesUpdate, params_);
}

void Simulation::step_impulses() {
  // Forces (soft bodies, cloth, ropes) are summed once; then the impulse stage runs its own
  // substeps on the contacts the lists hold (docs/architecture.md, "Impulse contacts"). Each:
  // gravity and forces into the velocities; the counting pass (every contact in reach counted,
  // the start velocities kept, the warm start applied); relaxing sweeps without position
  // correction, whose velocities and accumulated impulses the bodies and contacts keep; sweeps
  // with it on copies of those (split impulses), whose velocities move the pose; the pose; the
  // particles follow.
  Device& d = *device_;
  const int substeps = settings_.impulse_substeps;
  const int sweeps = (settings_.impulse_iterations + substeps - 1) / substeps;
  // Half the sweeps (rounded up) relax, the rest correct, on copies: the velocities and warm
  // starts the bodies keep never see the push out of an overlap (docs/architecture.md, "Impulse
  // contacts"). One sweep a substep corrects and keeps what it leaves.
  const bool split = sweeps >= 2;
  const int relaxing = split ? (sweeps + 1) / 2 : 0;
  const int correcting = sweeps - relaxing;
  shared::StepParams sub = params_;
  sub.gravity_dt.w = params_.gravity_dt.w / static_cast<float>(substeps);
  shared::StepParams velocity = sub;
  velocity.flags |= MOTES_FLAG_BODY_VELOCITY;
  shared::StepParams count = sub;
  count.flags |= MOTES_FLAG_IMPULSE_COUNT;
  shared::StepParams relax = sub;
  relax.flags |= MOTES_FLAG_IMPULSE_RELAX;
  shared::StepParams last = relax;  // the last relaxing sweep keeps its velocities and impulses
  last.flags |= MOTES_FLAG_IMPULSE_PUSH;
  shared::StepParams correct = sub;
  if (split) correct.flags |= MOTES_FLAG_IMPULSE_SPLIT;
  shared::StepParams pose = correct;
  pose.flags |= MOTES_FLAG_BODY_POSE;
  d.enqueue(Kernel::BodiesReduce, params_);
  for (int s = 0; s < substeps; ++s) {
    d.enqueue(Kernel::BodiesIntegrate, velocity);
    d.enqueue(Kernel::ImpulsesCompute, count);
    d.enqueue(Kernel::ImpulsesApply, count);
    for (int it = 0; it < relaxing; ++it) {
      d.enqueue(Kernel::ImpulsesCompute, it + 1 == relaxing ? last : relax);
      d.enqueue(Kernel::ImpulsesApply, it + 1 == relaxing ? last : relax);
    }
    for (int it = 0; it < correcting; ++it) {
      d.enqueue(Kernel::ImpulsesCompute, correct);
      d.enqueue(Kernel::ImpulsesApply, correct);
    }
    d.enqueue(Kernel::BodiesIntegrate, pose);
    d.enqueue(Kernel::ParticlesUpdate, sub);
  }
}

/// Jacobi sweeps of the velocity pass of position contacts per substep. One leaves a box sliding
/// down a slope 5% slower than g (sin - mu cos) (the normal velocity a correction gave is only
/// partly taken back, so friction sees too much normal push); two match it to 0.1%
/// (docs/position-solver.md).
constexpr int kPositionVelocitySweeps = 2;

/// Jacobi sweeps of the projection of position contacts per substep, each after the particles
/// have followed the last one's poses and the contacts have been counted again (a contact a sweep
/// made must share its bodies' inverse masses too, or mass splitting overshoots). With the stack
/// scaling of shared/position.h, columns of 10 boxes laid 10% of a diameter off centre drift
/// 0.02 to 0.04 d from 1 s to 4 s with 2 sweeps, under 0.01 d with 3 (docs/position-solver.md).
constexpr int kPositionProjectionSweeps = 3;

/// Jacobi sweeps of the position contacts of free spheres, soft-body, cloth and rope particles per
/// substep (shared/particle_shift.h), after the shape matching and the constraints, so that the
/// substep ends with the contacts met as far as the sweeps get (docs/position-solver.md).
constexpr int kParticleShiftSweeps = 3;

void Simulation::step_positions(const shared::StepParams& lists) {
  // Position contacts (docs/architecture.md, "Position contacts"; shared/position.h): each
  // substep predicts the poses with gravity, finds the contacts of the predicted particles (the
  // lists rebuilt first where a particle moved too far), counts each body's contacts, projects
  // them (kPositionProjectionSweeps Jacobi sweeps: the poses move, the motion becomes velocity),
  // then the velocity pass (kPositionVelocitySweeps Jacobi sweeps); the particles follow the poses
  // at the end of the step. Soft bodies, cloth and ropes (docs/architecture.md "Position contacts
  // of particles") are predicted with gravity alongside, pulled to their shapes and constraints
  // (attachments hand their pull to the bodies), and then moved out of their contacts
  // (kParticleShiftSweeps Jacobi sweeps, shared/particle_shift.h), the rigid bodies taking the
  // reactions of their contacts with them at each sweep.
  Device& d = *device_;
  const bool bodies = position_bodies_;
  const bool free = sizes_.particles > sizes_.rigid_particles;
  shared::StepParams project = params_;
  project.flags |= MOTES_FLAG_POSITION;
  shared::StepParams count = project;
  count.flags |= MOTES_FLAG_IMPULSE_COUNT;
  shared::StepParams first = project;
  first.flags |= MOTES_FLAG_POSITION_FIRST;
  shared::StepParams first_count = count;
  first_count.flags |= MOTES_FLAG_POSITION_FIRST;
  // The last count also bounds each body's step in the velocity pass (shared/contact_gram.h).
  shared::StepParams last_count = count;
  last_count.flags |= MOTES_FLAG_POSITION_GRAM;
  shared::StepParams velocity = project;
  velocity.flags |= MOTES_FLAG_POSITION_VELOCITY;
  shared::StepParams shift = project;
  shift.flags |= MOTES_FLAG_PARTICLE_SHIFT;
  // The rigid bodies take the reactions of their particles' contacts with the other kinds at the
  // same sweep, as a motion of their pose (particles_update hands each particle's to its body with
  // its moment, impulses_apply moves the body and keeps it as velocity), and their particles
  // follow.
  shared::StepParams react = shift;
  react.flags |= MOTES_FLAG_ABSORB;
  shared::StepParams react_apply = project;
  react_apply.flags |= MOTES_FLAG_ABSORB;
  // Adhesion's reactions are impulses: the bodies' velocities change, not their poses.
  shared::StepParams adhere_apply = velocity;
  adhere_apply.flags |= MOTES_FLAG_ABSORB;
  for (int s = 0; s < settings_.substeps; ++s) {
    if (bodies) {
      d.enqueue(Kernel::BodiesIntegrate, project);
      d.enqueue(Kernel::ParticlesUpdate, params_);
    }
    if (free) d.enqueue(Kernel::ParticlesIntegrate, project);
    d.enqueue(Kernel::NeighboursUpdate, lists);
    for (int it = 0; it < kPositionProjectionSweeps && bodies; ++it) {
      if (it > 0) d.enqueue(Kernel::ParticlesUpdate, params_);
      const shared::StepParams& c = it == 0                               ? first_count
                                    : it + 1 == kPositionProjectionSweeps ? last_count
                                                                          : count;
      d.enqueue(Kernel::ImpulsesCompute, c);
      d.enqueue(Kernel::ImpulsesApply, c);
      d.enqueue(Kernel::ImpulsesCompute, it == 0 ? first : project);
      d.enqueue(Kernel::ImpulsesApply, it == 0 ? first : project);
    }
    for (int it = 0; it < kPositionVelocitySweeps && bodies; ++it) {
      d.enqueue(Kernel::ImpulsesCompute, velocity);
      d.enqueue(Kernel::ImpulsesApply, velocity);
    }
    if (!free) continue;
    if (params_.cluster_count > 0) {
      d.enqueue(Kernel::ClustersFit, params_);
      d.enqueue(Kernel::ClustersGoal, params_);
    }
    relax_constraints();
    if (sizes_.absorb != 0) absorb_attachments();
    if (sizes_.fluid_particles != 0) relax_fluids(bodies);
    for (int it = 0; it < kParticleShiftSweeps; ++it) {
      d.enqueue(Kernel::ContactsCompute, project);
      d.enqueue(Kernel::ParticlesIntegrate, shift);
      if (bodies) {
        d.enqueue(Kernel::ParticlesUpdate, react);
        d.enqueue(Kernel::ImpulsesApply, react_apply);
        d.enqueue(Kernel::ParticlesUpdate, params_);
      }
    }
    if (sizes_.fluid_particles != 0) {
      // The fluids' velocity pass (docs/fluids.md, "The substep", 7): the vorticity and normals
      // of the substep's velocities, then XSPH viscosity, vorticity confinement, cohesion and
      // adhesion from them.
      d.enqueue(Kernel::FluidVorticity, params_);
      if (!fluid_adhesion_) {
        d.enqueue(Kernel::FluidVelocity, params_);
      } else {
        // The solids take adhesion's reaction (docs/fluids.md, "Solids in the density, and
        // two-way coupling"): a free particle into its velocity, a rigid body's as an impulse.
        shared::StepParams adhere = params_;
        adhere.flags |= MOTES_FLAG_FLUID_ADHESION;
        d.enqueue(Kernel::FluidVelocity, adhere);
        if (bodies) {
          d.enqueue(Kernel::ParticlesUpdate, react);
          d.enqueue(Kernel::ImpulsesApply, adhere_apply);
          d.enqueue(Kernel::ParticlesUpdate, params_);
        }
      }
    }
  }
  if (bodies) d.enqueue(Kernel::ParticlesUpdate, params_);
}

void Simulation::relax_fluids(bool bodies) {
  // Each sweep (docs/fluids.md, "The substep"): every fluid particle's density and lambda
  // (fluid_density; the substep's first sweep restarts the summed Lambda), its correction and the
  // solid particles' reactions (fluid_update), the fluid and the free solid particles moved by
  // them (particles_integrate's shift), and the rigid bodies take their particles' reactions as
  // the contact shifts' do.
  Device& d = *device_;
  shared::StepParams sweep = params_;
  sweep.flags |= MOTES_FLAG_POSITION;
  shared::StepParams first = sweep;
  first.flags |= MOTES_FLAG_POSITION_FIRST;
  shared::StepParams shift = sweep;
  shift.flags |= MOTES_FLAG_PARTICLE_SHIFT;
  shared::StepParams react = shift;
  react.flags |= MOTES_FLAG_ABSORB;
  shared::StepParams react_apply = sweep;
  react_apply.flags |= MOTES_FLAG_ABSORB;
  for (int it = 0; it < settings_.fluid_iterations; ++it) {
    d.enqueue(Kernel::FluidDensity, it == 0 ? first : sweep);
    d.enqueue(Kernel::FluidUpdate, sweep);
    d.enqueue(Kernel::ParticlesIntegrate, shift);
    if (bodies) {
      d.enqueue(Kernel::ParticlesUpdate, react);
      d.enqueue(Kernel::ImpulsesApply, react_apply);
      d.enqueue(Kernel::ParticlesUpdate, params_);
    }
  }
}

Status Simulation::clear_contact_history() {
  if (sizes_.impulse == 0) return Status::ok();
  Device& d = *device_;
  const std::vector<vec4> acc(buffer_layout(Buffer::ContactImpulse, sizes_).count, vec4(0.0f));
  const std::vector<std::uint32_t> stamp(sizes_.rigid_particles, 0u);
  Status s = write_vector(d, Buffer::ContactImpulse, acc);
  if (s) s = write_vector(d, Buffer::ImpulseStamp, stamp);
  return s;
}

std::vector<std::uint32_t> Simulation::scene_particle_order() const {
  // locate_particle's rule, body by body: O(N) where locate_particle is O(bodies) a particle.
  std::vector<std::uint32_t> order(sizes_.particles);
  for (std::uint32_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    const std::uint32_t at = device_index_[b];
    const std::uint32_t first = !info.has_body_state() ? at : rigid_first_[at];
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      order[first + k] = info.first_particle + k;
    }
  }
  return order;
}

Result<Snapshot> Simulation::snapshot() {
  Device& d = *device_;
  const std::size_t n = sizes_.particles;
  const std::size_t nb = sizes_.bodies;
  std::vector<vec4> ppos, pvel, bpos, bquat, bvel, bangmom, bangvel;
  Status st = read_vector(d, Buffer::ParticlePos, ppos, n);
  if (st) st = read_vector(d, Buffer::ParticleVel, pvel, n);
  if (st) st = read_vector(d, Buffer::BodyPos, bpos, nb);
  if (st) st = read_vector(d, Buffer::BodyQuat, bquat, nb);
  if (st) st = read_vector(d, Buffer::BodyVel, bvel, nb);
  if (st) st = read_vector(d, Buffer::BodyAngMom, bangmom, nb);
  if (st) st = read_vector(d, Buffer::BodyAngVel, bangvel, nb);
  std::vector<vec4> blow;
  if (st && sizes_.impulse != 0) st = read_vector(d, Buffer::BodyPosLow, blow, nb);
  std::vector<shared::ClusterFrame> frames;
  if (st) st = read_vector(d, Buffer::ClusterFrames, frames, sizes_.clusters);
  if (!st) return st;

  Snapshot s;
  s.cluster_rotation.reserve(frames.size());
  for (const shared::ClusterFrame& f : frames) s.cluster_rotation.push_back(f.rotation);
  s.time = time_;
  s.step = steps_;
  const std::size_t scene_bodies = bodies_.size();
  s.particle_pos.resize(n);
  s.particle_vel.resize(n);
  s.particle_body.resize(n);
  s.body_pos.resize(scene_bodies);
  s.body_quat.assign(scene_bodies, vec4(0.0f, 0.0f, 0.0f, 1.0f));
  s.body_vel.resize(scene_bodies);
  s.body_angmom.resize(scene_bodies);
  s.body_angvel.resize(scene_bodies);
  if (sizes_.impulse != 0) s.body_pos_low.assign(scene_bodies, vec4(0.0f));
  for (std::size_t b = 0; b < scene_bodies; ++b) {
    const BodyInfo& info = bodies_[b];
    const std::uint32_t at = device_index_[b];
    const std::uint32_t first = !info.has_body_state() ? at : rigid_first_[at];
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      s.particle_pos[info.first_particle + k] = ppos[first + k];
      s.particle_vel[info.first_particle + k] = pvel[first + k];
      s.particle_body[info.first_particle + k] = static_cast<std::uint32_t>(b);
    }
    if (info.linked || info.soft || info.fluid) {  // the mean of its particles, in double
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      double count = 0.0;
      for (std::uint32_t k = 0; k < info.particle_count; ++k) {
        const vec4 p = ppos[first + k];
        const vec4 u = pvel[first + k];
        // An emitter's waiting particles (inverse mass 0, 1 km below) are not in the liquid yet.
        if (info.fluid && !(u.w > 0.0f)) continue;
        x += Eigen::Vector3f(p.x, p.y, p.z).cast<double>();
        v += Eigen::Vector3f(u.x, u.y, u.z).cast<double>();
        count += 1.0;
      }
      if (count == 0.0) {  // an emitter before its first layer: at its nozzle, at rest
        for (const EmitterRange& e : emitters_) {
          if (e.entry == b) x = e.emitter.position;
        }
        count = 1.0;
      }
      s.body_pos[b] = to_vec4(x / count, 1.0 / info.mass);
      s.body_vel[b] = to_vec4(v / count, 0.0);
      s.body_angmom[b] = vec4(0.0f);
      s.body_angvel[b] = vec4(0.0f);
      continue;
    }
    if (info.free_sphere) {
      const vec4 p = ppos[at];
      const vec4 v = pvel[at];
      s.body_pos[b] = vec4(p.x, p.y, p.z, v.w);  // a one-particle body's inverse mass
      s.body_vel[b] = vec4(v.x, v.y, v.z, 0.0f);
      s.body_angmom[b] = vec4(0.0f);
      s.body_angvel[b] = vec4(0.0f);
      continue;
    }
    s.body_pos[b] = bpos[at];
    s.body_quat[b] = bquat[at];
    s.body_vel[b] = bvel[at];
    s.body_angmom[b] = bangmom[at];
    s.body_angvel[b] = bangvel[at];
    if (!blow.empty()) s.body_pos_low[b] = blow[at];
  }
  for (const auto& [b, q] : sphere_turns_) s.body_quat[b] = q;
  return s;
}

Status Simulation::write_state(const Snapshot& state) {
  const std::size_t n = sizes_.particles;
  const std::size_t nb = bodies_.size();
  if (state.particle_pos.size() != n || state.particle_vel.size() != n ||
      state.body_pos.size() != nb || state.body_quat.size() != nb || state.body_vel.size() != nb ||
      state.body_angmom.size() != nb || state.body_angvel.size() != nb) {
    return Status::error(fmt::format(
        "write_state: a state of {} particles and {} bodies for a simulation of {} and {}",
        state.particle_pos.size(), state.body_pos.size(), n, nb));
  }
  if (Status s = restore(state, false); !s) return s;
  steps_ = state.step;
  time_ = static_cast<double>(steps_) * settings_.dt;
  rebase_energy();  // a state from outside: the energy guard measures from it
  return count_emitted();
}

namespace {

/// ContactImpulse's slot of rigid device particle i with plane q (Buffer::ContactImpulse).
std::size_t plane_slot(const Sizes& sizes, std::uint32_t i, std::uint32_t q) {
  return (std::size_t{sizes.neighbour_capacity} + q) * sizes.rigid_particles + i;
}

}  // namespace

Status Simulation::read_plane_impulses(Snapshot& state) {
  state.plane_impulse.clear();
  if (sizes_.impulse == 0 || sizes_.planes == 0) return Status::ok();
  std::vector<vec4> acc;
  if (Status s = read_vector(*device_, Buffer::ContactImpulse, acc,
                             buffer_layout(Buffer::ContactImpulse, sizes_).count);
      !s) {
    return s;
  }
  state.plane_impulse.assign(std::size_t{sizes_.particles} * sizes_.planes, vec4(0.0f));
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    if (!info.has_body_state()) continue;
    const std::uint32_t first = rigid_first_[device_index_[b]];
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      for (std::uint32_t q = 0; q < sizes_.planes; ++q) {
        state.plane_impulse[(std::size_t{info.first_particle} + k) * sizes_.planes + q] =
            acc[plane_slot(sizes_, first + k, q)];
      }
    }
  }
  return Status::ok();
}

Status Simulation::restore(const Snapshot& state, bool rebuild) {
  Device& d = *device_;
  const std::size_t n = sizes_.particles;
  const std::size_t nb = sizes_.bodies;
  std::vector<vec4> ppos(n), pvel(n), bpos(nb), bquat(nb), bvel(nb), bangmom(nb), bangvel(nb);
  std::vector<vec4> blow(sizes_.impulse != 0 ? nb : 0, vec4(0.0f));
  const bool with_low = state.body_pos_low.size() == bodies_.size();
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    const std::uint32_t at = device_index_[b];
    const std::uint32_t first = !info.has_body_state() ? at : rigid_first_[at];
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      ppos[first + k] = state.particle_pos[info.first_particle + k];
      pvel[first + k] = state.particle_vel[info.first_particle + k];
    }
    if (!info.has_body_state()) continue;
    bpos[at] = state.body_pos[b];
    bquat[at] = state.body_quat[b];
    bvel[at] = state.body_vel[b];
    bangmom[at] = state.body_angmom[b];
    bangvel[at] = state.body_angvel[b];
    if (with_low && !blow.empty()) blow[at] = state.body_pos_low[b];
  }
  const std::uint32_t neighbour_state[4] = {1u, 0u, 0u, 0u};  // rebuild at the next step
  Status s = write_vector(d, Buffer::ParticlePos, ppos);
  if (s) s = write_vector(d, Buffer::ParticleVel, pvel);
  if (s) s = write_vector(d, Buffer::BodyPos, bpos);
  if (s) s = write_vector(d, Buffer::BodyQuat, bquat);
  if (s) s = write_vector(d, Buffer::BodyVel, bvel);
  if (s) s = write_vector(d, Buffer::BodyAngMom, bangmom);
  if (s) s = write_vector(d, Buffer::BodyAngVel, bangvel);
  if (s && !blow.empty()) s = write_vector(d, Buffer::BodyPosLow, blow);
  if (s && !rebuild && sizes_.partition != 0) s = write_vector(d, Buffer::PartitionRefPos, ppos);
  if (s && rebuild) s = d.write(Buffer::NeighbourState, neighbour_state, sizeof neighbour_state);
  if (s && rebuild) s = clear_contact_history();
  if (s && sizes_.impulse != 0 && sizes_.planes > 0 &&
      state.plane_impulse.size() == std::size_t{n} * sizes_.planes) {
    std::vector<vec4> acc;
    s = read_vector(d, Buffer::ContactImpulse, acc,
                    buffer_layout(Buffer::ContactImpulse, sizes_).count);
    for (std::size_t b = 0; s && b < bodies_.size(); ++b) {
      const BodyInfo& info = bodies_[b];
      if (!info.has_body_state()) continue;
      const std::uint32_t first = rigid_first_[device_index_[b]];
      for (std::uint32_t k = 0; k < info.particle_count; ++k) {
        for (std::uint32_t q = 0; q < sizes_.planes; ++q) {
          acc[plane_slot(sizes_, first + k, q)] =
              state.plane_impulse[(std::size_t{info.first_particle} + k) * sizes_.planes + q];
        }
      }
    }
    if (s) s = write_vector(d, Buffer::ContactImpulse, acc);
  }
  if (s && state.cluster_rotation.size() == sizes_.clusters && sizes_.clusters > 0) {
    std::vector<shared::ClusterFrame> frames;
    s = read_vector(d, Buffer::ClusterFrames, frames, sizes_.clusters);
    for (std::size_t k = 0; s && k < frames.size(); ++k) {
      frames[k].rotation = state.cluster_rotation[k];
    }
    if (s) s = write_vector(d, Buffer::ClusterFrames, frames);
  }
  if (!s) return s;
  return d.synchronize();
}

Status Simulation::set_body_velocities(const std::vector<Eigen::Vector3d>& velocity,
                                       const std::vector<Eigen::Vector3d>& angular) {
  const std::size_t count = bodies_.size();
  if (velocity.size() != count || (!angular.empty() && angular.size() != count)) {
    return Status::error(
        fmt::format("set_body_velocities: {} velocities and {} angular velocities for {} bodies",
                    velocity.size(), angular.size(), count));
  }
  for (std::size_t b = 0; b < count; ++b) {
    const bool moving = !velocity[b].isZero(0.0) || (!angular.empty() && !angular[b].isZero(0.0));
    if (!velocity[b].allFinite() || (!angular.empty() && !angular[b].allFinite())) {
      return Status::error(fmt::format("set_body_velocities: body {} '{}': not a finite velocity",
                                       b, bodies_[b].name));
    }
    if (bodies_[b].kind == BodyKind::Static && moving) {
      return Status::error(
          fmt::format("set_body_velocities: body {} '{}' is static: its velocity stays zero", b,
                      bodies_[b].name));
    }
    if ((bodies_[b].free_sphere || bodies_[b].linked || bodies_[b].fluid) && !angular.empty() &&
        !angular[b].isZero(0.0)) {
      return Status::error(fmt::format(
          "set_body_velocities: body {} '{}' is a {}, which has no angular velocity of its own: "
          "give its particles velocities instead",
          b, bodies_[b].name,
          bodies_[b].linked  ? "cloth or rope"
          : bodies_[b].fluid ? "fluid"
                             : "free sphere"));
    }
  }
  Result<Snapshot> snap = snapshot();
  if (!snap) return snap.status();
  Snapshot& state = snap.value();
  for (std::size_t b = 0; b < count; ++b) {
    const BodyInfo& info = bodies_[b];
    const vec4 v = to_vec4(velocity[b], 0.0);
    if (!info.has_body_state()) {  // every particle that is not pinned
      // A soft body turns about the mean of its particles: v + w x (x - mean).
      const vec4 mean = state.body_pos[b];
      const Eigen::Vector3d w =
          info.soft && !angular.empty() ? angular[b] : Eigen::Vector3d::Zero();
      for (std::uint32_t k = info.first_particle; k < info.first_particle + info.particle_count;
           ++k) {
        const vec4 old = state.particle_vel[k];
        const vec4 x = state.particle_pos[k];
        const Eigen::Vector3d r =
            Eigen::Vector3f(x.x - mean.x, x.y - mean.y, x.z - mean.z).cast<double>();
        const vec4 spin = to_vec4(velocity[b] + w.cross(r), 0.0);
        if (old.w != 0.0f) state.particle_vel[k] = vec4(spin.x, spin.y, spin.z, old.w);
      }
      continue;
    }
    state.body_vel[b] = v;
    if (angular.empty()) continue;
    // L = R diag(I) R^T w, in double, with the moments the body was uploaded with.
    const vec4 q = state.body_quat[b];
    const Eigen::Matrix3d rot =
        Eigen::Quaternionf(q.w, q.x, q.y, q.z).cast<double>().normalized().toRotationMatrix();
    const vec4 inv = rigid_inv_inertia_[device_index_[b]];
    const auto moment = [](float inverse) {
      return inverse > 0.0f ? 1.0 / static_cast<double>(inverse) : 0.0;
    };
    const Eigen::Vector3d moments(moment(inv.x), moment(inv.y), moment(inv.z));
    state.body_angvel[b] = to_vec4(angular[b], 0.0);
    state.body_angmom[b] = to_vec4(rot * moments.asDiagonal() * rot.transpose() * angular[b], 0.0);
  }
  if (Status s = restore(state); !s) return s;
  // The rigid particles' velocities from their bodies' new motion.
  if (sizes_.rigid_particles > 0) device_->enqueue(Kernel::ParticlesUpdate, params_);
  rebase_energy();  // energy from outside the scene: the energy guard measures from here
  return device_->synchronize();
}

Result<NeighbourStats> Simulation::neighbour_stats() {
  std::uint32_t words[4] = {};
  if (Status s = device_->read(Buffer::NeighbourState, words, sizeof words); !s) return s;
  NeighbourStats out;
  out.builds = words[MOTES_NEIGHBOUR_BUILDS];
  out.over_capacity = words[MOTES_NEIGHBOUR_OVER_CAPACITY];
  out.max_count = words[MOTES_NEIGHBOUR_MAX_COUNT];
  out.rebuild_pending = words[MOTES_NEIGHBOUR_REBUILD] != 0;
  return out;
}

void Simulation::queue_halo_pack() {
  shared::StepParams p = params_;
  p.halo_particles = halo_entries_[0];
  p.halo_bodies = halo_entries_[1];
  p.halo_first = 0;
  device_->enqueue(Kernel::HaloPack, p);
}

void Simulation::queue_halo_unpack() {
  shared::StepParams p = params_;
  p.halo_particles = halo_entries_[2];
  p.halo_bodies = halo_entries_[3];
  p.halo_first = halo_entries_[0] + halo_entries_[1];
  device_->enqueue(Kernel::HaloUnpack, p);
}

Status Simulation::halo_pack() {
  if (halo_out_count_ == 0) return device_->synchronize();
  queue_halo_pack();
  return device_->read(Buffer::HaloData, halo_out_.get(), halo_out_count_ * sizeof(vec4));
}

Status Simulation::halo_unpack() {
  if (halo_in_count_ == 0) return Status::ok();
  if (Status s = device_->write(Buffer::HaloData, halo_in_.get(), halo_in_count_ * sizeof(vec4));
      !s) {
    return s;
  }
  queue_halo_unpack();
  return Status::ok();
}

Result<std::vector<unsigned char>> Simulation::share_halo() {
  return device_->share_halo_outbox(std::max<std::size_t>(halo_out_count_, 1) * sizeof(vec4));
}

Status Simulation::halo_pack_direct() {
  if (halo_out_count_ == 0) return device_->synchronize();
  queue_halo_pack();
  if (Status s = device_->publish_halo_outbox(halo_out_count_ * sizeof(vec4)); !s) return s;
  return device_->synchronize();
}

Result<std::size_t> Simulation::open_peer_halo(const std::vector<unsigned char>& handle) {
  return device_->open_peer_outbox(handle);
}

Status Simulation::halo_unpack_direct(std::span<const HaloFetch> fetches) {
  if (halo_in_count_ == 0) return Status::ok();
  for (const HaloFetch& f : fetches) {
    if (f.to + f.count > halo_in_count_) {
      return Status::error(fmt::format("halo_unpack_direct: vec4s [{}, {}) of a halo of {}", f.to,
                                       f.to + f.count, halo_in_count_));
    }
    if (Status s = device_->fetch_peer_outbox(f.peer, f.from * sizeof(vec4), f.to * sizeof(vec4),
                                              f.count * sizeof(vec4));
        !s) {
      return s;
    }
  }
  queue_halo_unpack();
  return Status::ok();
}

Status Simulation::request_rebuild() {
  const std::uint32_t rebuild = 1;  // the first word, MOTES_NEIGHBOUR_REBUILD
  static_assert(MOTES_NEIGHBOUR_REBUILD == 0u);
  return device_->write(Buffer::NeighbourState, &rebuild, sizeof rebuild);
}

Result<double> Simulation::partition_displacement() {
  if (sizes_.partition == 0) {
    return Status::error("partition_displacement: a simulation without a partition reference");
  }
  device_->enqueue(Kernel::ParticlesDisplacement, params_);
  std::uint32_t bits = 0;
  if (Status s = device_->read(Buffer::PartitionCheck, &bits, sizeof bits); !s) return s;
  if (bits >= MOTES_PARTITION_NOT_FINITE) return std::numeric_limits<double>::infinity();
  return std::sqrt(static_cast<double>(std::bit_cast<float>(bits)));
}

namespace {

template <typename T>
void fnv1a(std::uint64_t& h, const std::vector<T>& v) {
  const auto* p = reinterpret_cast<const unsigned char*>(v.data());
  for (std::size_t i = 0; i < v.size() * sizeof(T); ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
}

bool finite(const vec4& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

}  // namespace

Result<std::uint64_t> Simulation::state_hash() {
  Result<Snapshot> s = snapshot();
  if (!s) return s.status();
  std::uint64_t h = 14695981039346656037ull;
  fnv1a(h, s->particle_pos);
  fnv1a(h, s->particle_vel);
  fnv1a(h, s->body_pos);
  fnv1a(h, s->body_quat);
  fnv1a(h, s->body_vel);
  fnv1a(h, s->body_angmom);
  return h;
}

Status Simulation::check_finite() {
  Result<Snapshot> s = snapshot();
  if (!s) return s.status();
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const bool ok = finite(s->body_pos[b]) && finite(s->body_quat[b]) && finite(s->body_vel[b]) &&
                    finite(s->body_angmom[b]);
    std::uint32_t bad_particle = std::numeric_limits<std::uint32_t>::max();
    const BodyInfo& info = bodies_[b];
    for (std::uint32_t i = info.first_particle; i < info.first_particle + info.particle_count;
         ++i) {
      if (!finite(s->particle_pos[i]) || !finite(s->particle_vel[i])) {
        bad_particle = i;
        break;
      }
    }
    if (!ok || bad_particle != std::numeric_limits<std::uint32_t>::max()) {
      const vec4 p = s->body_pos[b];
      return Status::error(fmt::format(
          "non-finite state at step {} (t = {} s): body {} '{}' position ({}, {}, {}){}; the "
          "time step is probably too large for the contact stiffness",
          steps_, time_, b, info.name, p.x, p.y, p.z,
          bad_particle == std::numeric_limits<std::uint32_t>::max()
              ? std::string()
              : fmt::format(", particle {}", bad_particle)));
    }
  }
  return Status::ok();
}

}  // namespace motes
