// motes::Simulation: owns the step and the host view of the state; runs on any Device.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "motes/scene.h"
#include "motes/status.h"
#include "shared/common.h"

namespace motes {

/// State read back from the device (vec4 layouts as in motes::Buffer).
struct Snapshot {
  double time = 0.0;
  std::uint64_t step = 0;
  std::vector<shared::vec4> particle_pos;  ///< xyz, w = radius
  std::vector<shared::vec4> particle_vel;  ///< xyz, w = inverse mass
  std::vector<std::uint32_t> particle_body;
  std::vector<shared::vec4> body_pos;  ///< centre of mass, w = inverse mass
  std::vector<shared::vec4> body_quat;
  std::vector<shared::vec4> body_vel;
  std::vector<shared::vec4> body_angmom;
  std::vector<shared::vec4> body_angvel;
};

/// Static facts about a body, kept on the host.
struct BodyInfo {
  std::string name;
  BodyKind kind = BodyKind::Dynamic;
  double mass = 0.0;
  std::uint32_t first_particle = 0;
  std::uint32_t particle_count = 0;
};

class Simulation {
 public:
  /// Builds the particles and bodies of a scene and uploads them to the device.
  static Result<std::unique_ptr<Simulation>> create(const Scene& scene,
                                                    std::unique_ptr<Device> device);

  /// Advances `count` steps of settings.dt (each settings.substeps substeps).
  Status step(std::uint64_t count = 1);

  /// Reads the state back (waits for the device).
  Result<Snapshot> snapshot();
  /// 64-bit FNV-1a hash of every particle and body buffer's bytes: equal hashes = equal states.
  Result<std::uint64_t> state_hash();
  /// Checks every body and particle for NaN or infinity; the error names step, body and particle.
  Status check_finite();

  /// Writes the dynamic state (bodies, particles, step, time) to a checkpoint file.
  Status save_state(const std::string& path);
  /// Restores a checkpoint written by save_state for the same scene (same particle and body
  /// counts). A missing, truncated or corrupt file, or one of another scene, is refused and the
  /// running state is left untouched.
  Status load_state(const std::string& path);

  [[nodiscard]] double time() const { return time_; }
  [[nodiscard]] std::uint64_t steps() const { return steps_; }
  [[nodiscard]] const Settings& settings() const { return settings_; }
  [[nodiscard]] std::uint32_t particle_count() const { return sizes_.particles; }
  [[nodiscard]] std::uint32_t body_count() const { return sizes_.bodies; }
  [[nodiscard]] const std::vector<BodyInfo>& bodies() const { return bodies_; }
  [[nodiscard]] const Sizes& sizes() const { return sizes_; }
  [[nodiscard]] const shared::StepParams& step_params() const { return params_; }
  [[nodiscard]] Device& device() { return *device_; }

 private:
  Simulation() = default;
  Status upload(const Scene& scene);

  std::unique_ptr<Device> device_;
  Settings settings_;
  Sizes sizes_;
  shared::StepParams params_{};
  std::vector<BodyInfo> bodies_;
  double time_ = 0.0;
  std::uint64_t steps_ = 0;
};

}  // namespace motes
