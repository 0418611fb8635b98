// Simulation::check_motion: the run-time motion guard (docs/reliability.md, "Guards while
// running"). The device reduces every particle to four words (Device::particles_check,
// shared/motion_check.h); the host turns them into a warning (tunnelling) or an error (a state
// that is not finite, or speeds no cause in the scene can give).
#include <fmt/format.h>

#include <bit>
#include <cmath>

#include "motes/simulation.h"
#include "shared/motion_check.h"

namespace motes {

std::pair<std::uint32_t, std::uint32_t> Simulation::locate_particle(std::uint32_t i) const {
  for (std::uint32_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    const std::uint32_t at = device_index_[b];
    const std::uint32_t first =
        info.free_sphere || info.linked || info.soft ? at : rigid_first_[at];
    if (i >= first && i - first < info.particle_count) {
      return {b, info.first_particle + (i - first)};
    }
  }
  return {0, i};
}

Result<MotionReport> Simulation::check_motion() {
  Device& d = *device_;
  d.particles_check(params_);
  std::uint32_t words[MOTES_MOTION_WORDS] = {};
  if (Status s = d.read(Buffer::MotionCheck, words, sizeof words); !s) return s;
  MotionReport r;
  r.step = steps_;
  r.time = time_;
  const double h = settings_.dt / settings_.substeps;

  if (words[MOTES_MOTION_NON_FINITE] != MOTES_MOTION_NONE) {
    const auto [b, particle] = locate_particle(words[MOTES_MOTION_NON_FINITE]);
    std::string detail;
    if (Result<Snapshot> s = snapshot(); s) {
      const shared::vec4 p = s->particle_pos[particle];
      const shared::vec4 v = s->particle_vel[particle];
      detail = fmt::format(": position ({}, {}, {}) m, velocity ({}, {}, {}) m/s", p.x, p.y, p.z,
                           v.x, v.y, v.z);
    }
    return Status::error(fmt::format(
        "non-finite state at step {} (t = {:.6g} s): particle {} of body {} '{}'{}; the run has "
        "gone unstable (dt {:.4g} s at substeps {} too large for the contact stiffness?)",
        steps_, time_, particle, b, bodies_[b].name, detail, settings_.dt, settings_.substeps));
  }
  if (words[MOTES_MOTION_FASTEST] == MOTES_MOTION_NONE || words[MOTES_MOTION_RATE2] == 0u) {
    if (!motion_started_) {
      motion_started_ = true;
      motion_start_time_ = time_;
    }
    return r;  // nothing moves
  }
  const auto [b, particle] = locate_particle(words[MOTES_MOTION_FASTEST]);
  r.moving = true;
  r.body = b;
  r.particle = particle;
  const double rate = std::sqrt(static_cast<double>(
      std::bit_cast<float>(words[MOTES_MOTION_RATE2])));  // diameters per second
  r.speed = std::sqrt(static_cast<double>(std::bit_cast<float>(words[MOTES_MOTION_SPEED2])));
  r.diameter = r.speed / rate;
  r.travel = rate * h;
  r.safe_dt = kSafeTravel / rate * settings_.substeps;
  if (!motion_started_) {
    motion_started_ = true;
    motion_start_speed_ = r.speed;
    motion_start_time_ = time_;
  }
  const double gravity = settings_.gravity.norm();
  const double contact_speed = kSafeTravel * r.diameter / h;
  const double reference =
      motion_start_speed_ + gravity * (time_ - motion_start_time_) + contact_speed;
  const BodyInfo& info = bodies_[b];
  if (r.speed > kBlowUpFactor * reference) {
    return Status::error(fmt::format(
        "speed out of bounds at step {} (t = {:.6g} s): particle {} of body {} '{}' moves at "
        "{:.4g} m/s ({:.4g} of its diameter per substep), more than {:.0f} times the {:.4g} m/s "
        "that the start ({:.4g} m/s), gravity since then and the contact scale ({:.4g} m/s: {} "
        "of a diameter per substep) account for; the run has gone unstable (dt {:.4g} s at "
        "substeps {} too large for the contact stiffness?)",
        steps_, time_, particle, b, info.name, r.speed, r.travel, kBlowUpFactor, reference,
        motion_start_speed_, contact_speed, kSafeTravel, settings_.dt, settings_.substeps));
  }
  if (r.travel > kSafeTravel) {
    r.warning = fmt::format(
        "step {} (t = {:.6g} s): particle {} of body {} '{}' moves {:.3g} of its diameter "
        "({:.4g} m) per substep at {:.4g} m/s, more than the {} that contacts are resolved at: "
        "contacts can be missed (tunnelling); the largest safe dt at this speed is {:.4g} s at "
        "substeps {} (dt is {:.4g} s)",
        steps_, time_, particle, b, info.name, r.travel, r.diameter, r.speed, kSafeTravel,
        r.safe_dt, settings_.substeps, settings_.dt);
  }
  return r;
}

}  // namespace motes
