// Simulation::check_motion: the run-time motion and energy guards (docs/reliability.md, "Guards
// while running"). The device reduces every particle to four words (Device::particles_check,
// shared/motion_check.h) and every body and free particle to a few words per block of 256
// (Device::energy_reduce, shared/energy.h); the host turns them into a warning (tunnelling) or an
// error (a state that is not finite, energy no cause in the scene can give, or a particle faster
// than any energy the scene may have could make it).
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "motes/simulation.h"
#include "shared/energy.h"
#include "shared/motion_check.h"

namespace motes {

namespace {

/// |xyz| in double.
double norm3(const shared::vec4& v) {
  const auto x = static_cast<double>(v.x);
  const auto y = static_cast<double>(v.y);
  const auto z = static_cast<double>(v.z);
  return std::sqrt(x * x + y * y + z * z);
}

/// Text for the fastest particle of scene body `b` in a snapshot: "particle P at V m/s", with the
/// body's spin when it has one.
std::string fastest_of_body(const Snapshot& s, const BodyInfo& info, std::uint32_t b) {
  std::uint32_t fastest = info.first_particle;
  double speed = -1.0;
  for (std::uint32_t k = info.first_particle;
       k < info.first_particle + info.particle_count && k < s.particle_vel.size(); ++k) {
    const double u = norm3(s.particle_vel[k]);
    if (u > speed) {
      speed = u;
      fastest = k;
    }
  }
  std::string text = fmt::format("particle {} at {:.4g} m/s", fastest, speed);
  if (b < s.body_angvel.size()) {
    const double spin = norm3(s.body_angvel[b]);
    if (spin > 0.0) text += fmt::format(", spinning at {:.4g} rad/s", spin);
  }
  return text;
}

}  // namespace

std::pair<std::uint32_t, std::uint32_t> Simulation::locate_particle(std::uint32_t i) const {
  for (std::uint32_t b = 0; b < bodies_.size(); ++b) {
    const BodyInfo& info = bodies_[b];
    const std::uint32_t at = device_index_[b];
    const std::uint32_t first = !info.has_body_state() ? at : rigid_first_[at];
    if (i >= first && i - first < info.particle_count) {
      return {b, info.first_particle + (i - first)};
    }
  }
  return {0, i};
}

std::pair<std::uint32_t, std::uint32_t> Simulation::locate_item(std::uint32_t j) const {
  if (j == MOTES_ENERGY_NONE) return {MechanicalEnergy::kNone, MechanicalEnergy::kNone};
  if (j < sizes_.bodies) return {rigid_scene_body_[j], MechanicalEnergy::kNone};
  return locate_particle(sizes_.rigid_particles + (j - sizes_.bodies));
}

Result<Simulation::DeviceEnergy> Simulation::read_energy() {
  std::vector<std::uint32_t> words(buffer_layout(Buffer::EnergyPartials, sizes_).count);
  if (Status s = device_->read(Buffer::EnergyPartials, words.data(), words.size() * 4); !s) {
    return s;
  }
  // The blocks in order, in double: the first block's largest item wins a tie (the lowest item).
  DeviceEnergy e;
  bool any = false;
  for (std::size_t at = MOTES_ENERGY_HEADER; at + MOTES_ENERGY_WORDS <= words.size();
       at += MOTES_ENERGY_WORDS) {
    e.kinetic += static_cast<double>(std::bit_cast<float>(words[at + MOTES_ENERGY_KINETIC]));
    e.potential += static_cast<double>(std::bit_cast<float>(words[at + MOTES_ENERGY_POTENTIAL]));
    const std::uint32_t item = words[at + MOTES_ENERGY_MAX_ITEM];
    const auto largest =
        static_cast<double>(std::bit_cast<float>(words[at + MOTES_ENERGY_MAX_KINETIC]));
    if (item != MOTES_ENERGY_NONE && (!any || largest > e.largest_kinetic)) {
      any = true;
      e.largest_kinetic = largest;
      e.largest_item = item;
    }
  }
  return e;
}

Result<MotionReport> Simulation::check_motion() {
  Device& d = *device_;
  d.enqueue(Kernel::ParticlesCheck, params_);
  d.enqueue(Kernel::EnergyReduce, params_);
  std::uint32_t words[MOTES_MOTION_WORDS] = {};
  if (Status s = d.read(Buffer::MotionCheck, words, sizeof words); !s) return s;
  Result<DeviceEnergy> energy = read_energy();
  if (!energy) return energy.status();
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

  // The energy guard: the reference at the first check (and after the state was changed from
  // outside), with the contact law's stored energy and the margin from a snapshot then.
  r.kinetic_energy = energy->kinetic;
  r.potential_energy = energy->potential;
  r.energy = r.kinetic_energy + r.potential_energy;
  if (!energy_started_) {
    Result<Snapshot> s = snapshot();
    if (!s) return s.status();
    MechanicalEnergy measured;
    measured.kinetic = energy->kinetic;
    measured.potential = energy->potential;
    energy_reference_ =
        energy_reference(s.value(), bodies_, energy_model_, settings_.gravity, measured);
    energy_started_ = true;
    largest_rise_ = r.energy - energy_reference_.energy();
  }
  r.reference = energy_reference_;
  r.rise = r.energy - energy_reference_.energy();
  largest_rise_ = std::max(largest_rise_, r.rise);
  r.largest_rise = largest_rise_;
  r.largest_kinetic = energy->largest_kinetic;
  std::tie(r.largest_kinetic_body, r.largest_kinetic_particle) = locate_item(energy->largest_item);
  r.speed_limit = energy_speed_limit(energy_reference_, energy_model_, r.potential_energy);
  const EnergyReference& ref = energy_reference_;
  const GuardPlace at{steps_, time_, settings_.dt, static_cast<int>(settings_.substeps)};
  if (!std::isfinite(r.energy) || !(r.energy <= ref.limit(r.kinetic_energy))) {
    std::string who = "no body has kinetic energy";
    if (r.largest_kinetic_body != MechanicalEnergy::kNone) {
      const std::uint32_t b = r.largest_kinetic_body;
      std::string where;
      if (Result<Snapshot> s = snapshot(); !s) {
        where = s.message();
      } else if (r.largest_kinetic_particle != MechanicalEnergy::kNone) {
        where = fmt::format("particle {} at {:.4g} m/s", r.largest_kinetic_particle,
                            norm3(s->particle_vel[r.largest_kinetic_particle]));
      } else {
        where = fastest_of_body(s.value(), bodies_[b], b);
      }
      who = fmt::format("body {} '{}' has the most kinetic energy, {:.4g} J ({})", b,
                        bodies_[b].name, r.largest_kinetic, where);
    }
    return Status::error(energy_error(ref, r.kinetic_energy, r.potential_energy, at, who));
  }

  if (words[MOTES_MOTION_FASTEST] == MOTES_MOTION_NONE || words[MOTES_MOTION_RATE2] == 0u) {
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
  const BodyInfo& info = bodies_[b];
  if (std::string e = energy_speed_error(ref, energy_model_, r.potential_energy, r.speed,
                                         r.speed_limit, particle, b, info.name, at);
      !e.empty()) {
    return Status::error(e);
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
