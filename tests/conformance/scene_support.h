// Whole-scene helpers for test_scenes.cpp: the example scenes, simulations on a chosen device,
// copying the dynamic state between simulations, and the oracle's copy of a simulation.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/status.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {

/// examples/scenes/<name>, loaded once per process (the bunny is voxelized on load).
const motes::Result<motes::Scene>& example_scene(const std::string& name);

/// The scene `seconds` later, for bodies in free fall that do not turn (dice, bunny) and cloths
/// and ropes without pins: positions advanced by v t + g t^2 / 2, velocities by g t. Skips the
/// uneventful fall before the first contact, which would cost thousands of steps.
motes::Scene fast_forward(motes::Scene scene, double seconds);

/// A simulation of `scene` on device `index` of `backend`.
motes::Result<std::unique_ptr<motes::Simulation>> simulate(const motes::Scene& scene,
                                                           const std::string& backend, int index);

/// The dynamic state of a simulation: what Simulation::save_state keeps.
struct DynamicState {
  std::vector<vec4> particle_pos, particle_vel;
  std::vector<vec4> body_pos, body_quat, body_vel, body_angmom, body_angvel;
  std::vector<motes_ref::ClusterFrame> cluster_frames;  ///< soft bodies: the rotations start fits
};
motes::Status read_state(motes::Simulation& sim, DynamicState& out);
motes::Status write_state(motes::Simulation& sim, const DynamicState& state);

/// The oracle's copy of a simulation: every buffer a step reads, and the launch parameters.
struct OracleRun {
  motes_ref::Particles particles;
  motes_ref::Bodies bodies;
  std::vector<ContactLaw> laws;
  std::vector<PlaneData> planes;
  StepParams params{};
  int substeps = 1;
  /// Cloth and ropes: the coloured constraints, relaxed `iterations` times per substep.
  std::vector<motes_ref::Constraint> constraints;
  std::vector<uint> colour_first;
  int iterations = 0;
  /// Soft bodies: clusters, members and the last fit.
  std::vector<motes_ref::Cluster> clusters;
  std::vector<motes_ref::ClusterMember> members;
  std::vector<motes_ref::ClusterFrame> frames;
  /// Cloth and ropes attached to rigid bodies (Sizes::absorb): the bodies take the constraints'
  /// pull after the sweeps.
  bool absorb = false;
  /// Advances `steps` steps with motes_ref::step (each settings.substeps substeps), then the
  /// soft bodies' clusters (motes_ref::clusters_fit, clusters_goal), the constraints colour by
  /// colour (motes_ref::constraints_solve) and, with `absorb`, the bodies' share
  /// (motes_ref::absorbed_impulses, impulses_apply, particles_update), as Simulation::step does.
  void step(std::uint64_t steps);
};
motes::Status capture(motes::Simulation& sim, OracleRun& out);

}  // namespace motes_conf
