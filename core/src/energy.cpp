// The energy guard on the host (motes/energy.h): a Snapshot's mechanical energy, the scene's
// energy model (contact rules in the scene's order, masses, the speed bound's factor), the stored
// contact energy by a hash grid, and the reference E0 with its margin.
#include "motes/energy.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "contact_laws.h"
#include "motes/cloth.h"
#include "motes/fluid.h"
#include "motes/shapes.h"
#include "motes/simulation.h"
#include "shared/links.h"

namespace motes {

namespace {

/// An emitter's particle that has not left yet (a fluid's particle of inverse mass 0): it sits
/// far below its nozzle and counts for nothing (docs/fluids.md, "Emitters").
bool parked(const Snapshot& state, std::span<const BodyInfo> bodies, std::size_t i) {
  if (i >= state.particle_body.size() || i >= state.particle_vel.size()) return false;
  const std::uint32_t b = state.particle_body[i];
  return b < bodies.size() && bodies[b].fluid && !(state.particle_vel[i].w > 0.0f);
}

using shared::vec4;

Eigen::Vector3d to_eigen(const vec4& v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
}

bool finite3(const vec4& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// A rigid body's factor c = sqrt(1 + m lambda), lambda the largest eigenvalue of
/// I^-1 (|r|^2 1 - r r^T) over its particles' offsets r from the centre of mass (shape frame):
/// |w x r|^2 <= lambda w.I w = 2 lambda K_rot, so a particle moves at most
/// sqrt(2 K_lin / m) + sqrt(2 lambda K_rot) <= sqrt(2 K / m) sqrt(1 + m lambda) (Cauchy-Schwarz,
/// K = K_lin + K_rot).
double rigid_speed_factor(const ParticleSet& shape, const MassProperties& mp) {
  const Eigen::LLT<Eigen::Matrix3d> llt(mp.inertia);
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  // With I = L L^T: lambda_max(I^-1 A) = lambda_max(L^-1 A L^-T), and L^-1 A L^-T =
  // |r|^2 P - q q^T with P = L^-1 L^-T and q = L^-1 r.
  const Eigen::Matrix3d inv_l = llt.matrixL().solve(Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d p = inv_l * inv_l.transpose();
  double lambda = 0.0;
  for (const Eigen::Vector3f& point : shape.points) {
    const Eigen::Vector3d r = point.cast<double>() - mp.center;
    const Eigen::Vector3d q = inv_l * r;
    const Eigen::Matrix3d s = r.squaredNorm() * p - q * q.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(s, Eigen::EigenvaluesOnly);
    lambda = std::max(lambda, solver.eigenvalues().maxCoeff());
  }
  return std::sqrt(1.0 + mp.mass * lambda);
}

/// Height along -g (m per unit |g|): larger is higher; 0 for every point without gravity.
double height(const Eigen::Vector3d& x, const Eigen::Vector3d& down) { return -down.dot(x); }

}  // namespace

MechanicalEnergy mechanical_energy(const Snapshot& state, std::span<const BodyInfo> bodies,
                                   const Eigen::Vector3d& gravity,
                                   const Eigen::Vector3d& reference) {
  MechanicalEnergy e;
  bool any = false;
  const auto item = [&](double kinetic, double mass, const Eigen::Vector3d& x, std::uint32_t body,
                        std::uint32_t particle) {
    e.kinetic += kinetic;
    e.potential -= mass * gravity.dot(x - reference);
    if (!any || kinetic > e.largest_kinetic) {
      any = true;
      e.largest_kinetic = kinetic;
      e.largest_body = body;
      e.largest_particle = particle;
    }
  };
  for (std::size_t b = 0; b < bodies.size() && b < state.body_pos.size(); ++b) {
    const BodyInfo& info = bodies[b];
    const auto body = static_cast<std::uint32_t>(b);
    if (info.linked || info.soft || info.fluid) {  // by its particles
      for (std::uint32_t k = info.first_particle;
           k < info.first_particle + info.particle_count && k < state.particle_pos.size(); ++k) {
        const vec4& x = state.particle_pos[k];
        const vec4& v = state.particle_vel[k];
        if (!(v.w > 0.0f) || !std::isfinite(v.w) || !finite3(x) || !finite3(v)) continue;
        const double mass = 1.0 / static_cast<double>(v.w);
        item(0.5 * mass * to_eigen(v).squaredNorm(), mass, to_eigen(x), body, k);
      }
      continue;
    }
    const vec4& x = state.body_pos[b];
    const vec4& v = state.body_vel[b];
    const vec4& w = state.body_angvel[b];
    const vec4& l = state.body_angmom[b];
    if (!(x.w > 0.0f) || !std::isfinite(x.w) || !finite3(x) || !finite3(v) || !finite3(w) ||
        !finite3(l)) {
      continue;
    }
    const double mass = 1.0 / static_cast<double>(x.w);
    const double kinetic =
        0.5 * mass * to_eigen(v).squaredNorm() + 0.5 * to_eigen(w).dot(to_eigen(l));
    item(kinetic, mass, to_eigen(x), body,
         info.free_sphere ? info.first_particle : MechanicalEnergy::kNone);
  }
  return e;
}

EnergyModel energy_model(const Scene& scene) {
  EnergyModel m;
  const bool impulses = rigid_contacts_without_forces(scene.settings.contact_model);
  // Position contacts have no force law anywhere: no spring stores energy (shared/position.h,
  // shared/particle_shift.h).
  const bool positions = scene.settings.contact_model == ContactModel::Positions;
  m.materials = static_cast<std::uint32_t>(scene.materials.size());
  m.substep = scene.settings.dt / static_cast<double>(std::max(scene.settings.substeps, 1));
  m.laws = contact_law_table(scene.materials);
  for (const PlaneSpec& pl : scene.planes) {
    const Eigen::Vector3d n = pl.normal.normalized();
    shared::PlaneData pd{};
    pd.normal_offset = vec4(static_cast<float>(n.x()), static_cast<float>(n.y()),
                            static_cast<float>(n.z()), static_cast<float>(n.dot(pl.point)));
    pd.material = static_cast<std::uint32_t>(pl.material);
    m.planes.push_back(pd);
  }
  std::size_t particles = 0;
  for (const BodySpec& b : scene.bodies) particles += b.shape ? b.shape->points.size() : 0;
  for (const LinkedSpec& l : scene.linked) particles += l.points.size();
  for (const FluidSpec& f : scene.fluids) particles += f.points.size();
  m.contact_word.reserve(particles);
  m.material.reserve(particles);
  m.by_impulse.reserve(particles);

  // Every item's mass and speed factor c: the factor is the largest c sqrt(lightest / m).
  std::vector<std::pair<double, double>> items;  // (mass, c), one per distinct kind of item
  const auto add_item = [&](double mass, double c) {
    if (!(mass > 0.0) || !std::isfinite(mass)) return;
    if (items.empty() || items.back() != std::make_pair(mass, c)) items.emplace_back(mass, c);
  };
  // Repeated bodies share a shape: its mass properties and factor once per (shape, material).
  std::map<std::pair<const ParticleSet*, int>, std::pair<MassProperties, double>> shapes;
  for (std::size_t bi = 0; bi < scene.bodies.size(); ++bi) {
    const BodySpec& b = scene.bodies[bi];
    if (!b.shape || b.shape->points.empty()) continue;
    const auto material = static_cast<std::uint32_t>(std::max(b.material, 0));
    for (std::size_t k = 0; k < b.shape->points.size(); ++k) {
      m.contact_word.push_back(static_cast<std::uint32_t>(bi));
      m.material.push_back(material);
      m.by_impulse.push_back((impulses && !b.soft) || positions ? 1u : 0u);
    }
    m.largest_diameter = std::max(m.largest_diameter, b.shape->diameter);
    if (b.kind != BodyKind::Dynamic || material >= scene.materials.size()) continue;
    const auto key = std::make_pair(b.shape.get(), b.material);
    auto found = shapes.find(key);
    if (found == shapes.end()) {
      const MassProperties mp = mass_properties(*b.shape, scene.materials[material].density);
      const double c = b.soft ? 1.0 : rigid_speed_factor(*b.shape, mp);
      found = shapes.emplace(key, std::make_pair(mp, c)).first;
    }
    const auto& [mp, c] = found->second;
    m.dynamic_mass += mp.mass;
    if (b.soft) {
      add_item(mp.particle_mass, 1.0);
    } else {
      add_item(mp.mass, c);
    }
  }
  const bool any_mesh = std::any_of(scene.linked.begin(), scene.linked.end(),
                                    [](const LinkedSpec& l) { return l.lattice.empty(); });
  // Particle i's list is exclusion_list [exclusion_start[i], exclusion_start[i + 1]): empty for
  // the bodies' particles.
  if (any_mesh) m.exclusion_start.assign(m.contact_word.size(), 0u);
  for (std::size_t li = 0; li < scene.linked.size(); ++li) {
    const LinkedSpec& l = scene.linked[li];
    const auto object = static_cast<std::uint32_t>(li);
    const auto first = static_cast<std::uint32_t>(m.contact_word.size());
    const auto count = static_cast<std::uint32_t>(l.points.size());
    const bool mesh = l.lattice.empty();
    const LinkNeighbourhoods near =
        mesh ? link_neighbourhoods(l.links, count) : LinkNeighbourhoods{};
    for (std::uint32_t k = 0; k < count; ++k) {
      m.contact_word.push_back(
          mesh ? shared::linked_mesh_body(object, k)
               : shared::linked_body(object, l.lattice[k][0] & 1023u, l.lattice[k][1] & 1023u));
      m.material.push_back(static_cast<std::uint32_t>(std::max(l.material, 0)));
      m.by_impulse.push_back(positions ? 1u : 0u);
      if (any_mesh)
        m.exclusion_start.push_back(static_cast<std::uint32_t>(m.exclusion_list.size()));
      if (mesh) {
        for (std::uint32_t e = near.start[k]; e < near.start[k + 1]; ++e) {
          m.exclusion_list.push_back(first + near.list[e]);
        }
      }
    }
    m.largest_diameter = std::max(m.largest_diameter, l.diameter);
    if (l.material < 0 || static_cast<std::size_t>(l.material) >= scene.materials.size()) continue;
    const double mass = linked_particle_mass(
        scene.materials[static_cast<std::size_t>(l.material)].density, l.diameter);
    std::vector<bool> pinned(count, false);
    for (const std::uint32_t k : l.pinned) {
      if (k < count) pinned[k] = true;
    }
    const auto free = static_cast<double>(std::count(pinned.begin(), pinned.end(), false));
    m.dynamic_mass += mass * free;
    if (free > 0.0) add_item(mass, 1.0);
  }
  // Fluids (after the cloths and ropes): free particles whose only contacts are position
  // contacts, each its own body (none of them stores energy in a spring).
  for (std::size_t fi = 0; fi < scene.fluids.size(); ++fi) {
    const FluidSpec& f = scene.fluids[fi];
    const auto material = static_cast<std::uint32_t>(std::max(f.material, 0));
    for (std::size_t k = 0; k < f.points.size(); ++k) {
      m.contact_word.push_back(
          static_cast<std::uint32_t>(scene.bodies.size() + scene.linked.size() + fi));
      m.material.push_back(material);
      m.by_impulse.push_back(1u);
      if (any_mesh) {
        m.exclusion_start.push_back(static_cast<std::uint32_t>(m.exclusion_list.size()));
      }
    }
    m.largest_diameter = std::max(m.largest_diameter, f.diameter);
    if (material >= scene.materials.size()) continue;
    const double mass = fluid_particle_mass(scene.materials[material], f.diameter);
    m.dynamic_mass += mass * static_cast<double>(f.points.size());
    add_item(mass, 1.0);
  }
  if (any_mesh) m.exclusion_start.push_back(static_cast<std::uint32_t>(m.exclusion_list.size()));
  for (const auto& [mass, c] : items) {
    m.lightest_mass = m.lightest_mass == 0.0 ? mass : std::min(m.lightest_mass, mass);
  }
  for (const auto& [mass, c] : items) {
    m.speed_factor = std::max(m.speed_factor, c * std::sqrt(m.lightest_mass / mass));
  }
  return m;
}

double contact_energy(const Snapshot& state, const EnergyModel& model) {
  const std::size_t n = std::min(state.particle_pos.size(), model.contact_word.size());
  if (n == 0 || model.materials == 0 || state.particle_vel.size() < n) return 0.0;
  const auto law = [&](std::uint32_t a, std::uint32_t b) -> const shared::ContactLaw& {
    return model.laws[std::size_t{a} * model.materials + b];
  };
  double energy = 0.0;
  // Planes: every dynamic particle that feels the contact law.
  for (std::size_t i = 0; i < n && !model.planes.empty(); ++i) {
    const vec4& x = state.particle_pos[i];
    if (!(state.particle_vel[i].w > 0.0f) || model.by_impulse[i] != 0 || !finite3(x)) continue;
    for (const shared::PlaneData& pl : model.planes) {
      const double gap =
          to_eigen(pl.normal_offset).dot(to_eigen(x)) - static_cast<double>(pl.normal_offset.w);
      const double overlap = static_cast<double>(x.w) - gap;
      if (overlap > 0.0) {
        energy += 0.5 * static_cast<double>(law(model.material[i], pl.material).stiffness) *
                  overlap * overlap;
      }
    }
  }
  // Pairs, through a hash grid of cells of the largest diameter: a pair that overlaps is in the
  // same cell or a neighbouring one. Each bucket is visited once per particle (the 27 cells'
  // buckets deduplicated), each pair once (j > i).
  double diameter = 0.0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  bool have_origin = false;
  for (std::size_t i = 0; i < n; ++i) {
    const vec4& x = state.particle_pos[i];
    if (!finite3(x)) continue;
    diameter = std::max(diameter, 2.0 * static_cast<double>(x.w));
    if (!have_origin) {
      origin = to_eigen(x);
      have_origin = true;
    }
  }
  if (!(diameter > 0.0) || !std::isfinite(diameter)) return energy;
  const std::uint64_t table = std::bit_ceil(std::max<std::uint64_t>(2 * n, 64));
  const auto cell_of = [&](const vec4& x) {
    const Eigen::Vector3d c = ((to_eigen(x) - origin) / diameter).array().floor();
    const auto clamp = [](double v) {
      return static_cast<std::int64_t>(std::clamp(v, -1.0e15, 1.0e15));
    };
    return std::array<std::int64_t, 3>{clamp(c.x()), clamp(c.y()), clamp(c.z())};
  };
  const auto bucket_of = [&](const std::array<std::int64_t, 3>& c) {
    std::uint64_t h = static_cast<std::uint64_t>(c[0]) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(c[1]) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= static_cast<std::uint64_t>(c[2]) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return (h ^ (h >> 29)) & (table - 1);
  };
  std::vector<std::uint64_t> bucket(n, table);  // table: not finite, in no bucket
  std::vector<std::uint32_t> start(table + 1, 0u);
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite3(state.particle_pos[i])) continue;
    bucket[i] = bucket_of(cell_of(state.particle_pos[i]));
    ++start[bucket[i] + 1];
  }
  for (std::uint64_t b = 0; b < table; ++b) start[b + 1] += start[b];
  std::vector<std::uint32_t> sorted(start[table]);
  {
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      if (bucket[i] < table) sorted[next[bucket[i]]++] = static_cast<std::uint32_t>(i);
    }
  }
  const auto excluded = [&](std::size_t i, std::size_t j) {
    const std::uint32_t wi = model.contact_word[i];
    const std::uint32_t wj = model.contact_word[j];
    if (shared::contact_excluded(wi, wj)) return true;
    if (!shared::contact_listed(wi, wj) || model.exclusion_start.size() <= i + 1) return false;
    const auto first = model.exclusion_list.begin() + model.exclusion_start[i];
    const auto last = model.exclusion_list.begin() + model.exclusion_start[i + 1];
    return std::binary_search(first, last, static_cast<std::uint32_t>(j));
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (bucket[i] >= table) continue;
    const vec4& xi = state.particle_pos[i];
    const bool dynamic_i = state.particle_vel[i].w > 0.0f;
    const std::array<std::int64_t, 3> c = cell_of(xi);
    std::array<std::uint64_t, 27> near{};
    std::size_t count = 0;
    for (std::int64_t dz = -1; dz <= 1; ++dz) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          near[count++] = bucket_of({c[0] + dx, c[1] + dy, c[2] + dz});
        }
      }
    }
    std::sort(near.begin(), near.end());
    const auto end = std::unique(near.begin(), near.end());
    for (auto b = near.begin(); b != end; ++b) {
      for (std::uint32_t t = start[*b]; t < start[*b + 1]; ++t) {
        const std::uint32_t j = sorted[t];
        if (j <= i) continue;
        if (!dynamic_i && !(state.particle_vel[j].w > 0.0f)) continue;  // static with static
        if (model.by_impulse[i] != 0 && model.by_impulse[j] != 0) continue;
        const vec4& xj = state.particle_pos[j];
        const double rsum = static_cast<double>(xi.w) + static_cast<double>(xj.w);
        const double dist2 = (to_eigen(xj) - to_eigen(xi)).squaredNorm();
        if (dist2 >= rsum * rsum || dist2 == 0.0 || excluded(i, j)) continue;
        const double overlap = rsum - std::sqrt(dist2);
        energy += 0.5 * static_cast<double>(law(model.material[i], model.material[j]).stiffness) *
                  overlap * overlap;
      }
    }
  }
  return energy;
}

EnergyReference energy_reference(const Snapshot& state, std::span<const BodyInfo> bodies,
                                 const EnergyModel& model, const Eigen::Vector3d& gravity,
                                 const MechanicalEnergy& measured) {
  EnergyReference r;
  r.step = state.step;
  r.time = state.time;
  r.kinetic = measured.kinetic;
  r.potential = measured.potential;
  r.contact = contact_energy(state, model);
  const double g = gravity.norm();
  if (g > 0.0) {
    // The lowest particle, static ones included: what the dynamic items could fall to.
    const Eigen::Vector3d down = gravity / g;
    Eigen::Vector3d lowest = Eigen::Vector3d::Zero();
    double lowest_height = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < state.particle_pos.size(); ++i) {
      const vec4& x = state.particle_pos[i];
      if (!finite3(x) || parked(state, bodies, i)) continue;
      const double h = height(to_eigen(x), down);
      if (h < lowest_height) {
        lowest_height = h;
        lowest = to_eigen(x);
      }
    }
    if (std::isfinite(lowest_height)) {
      r.height = std::max(0.0, mechanical_energy(state, bodies, gravity, lowest).potential);
    }
  }
  // The largest coordinate: the rounding of positions there, over a substep, is the velocity
  // noise of particles whose velocities come from position corrections.
  float coordinate = static_cast<float>(model.largest_diameter);
  for (std::size_t i = 0; i < state.particle_pos.size(); ++i) {
    const vec4& x = state.particle_pos[i];
    if (!finite3(x) || parked(state, bodies, i)) continue;
    coordinate = std::max({coordinate, std::abs(x.x), std::abs(x.y), std::abs(x.z)});
  }
  const double ulp = static_cast<double>(std::nextafter(coordinate, HUGE_VALF) - coordinate);
  const double noise = model.substep > 0.0 ? kEnergyRoundingUlps * ulp / model.substep : 0.0;
  r.floor = model.dynamic_mass * (g * model.largest_diameter + 0.5 * noise * noise);
  r.margin = kEnergyMarginFraction * (std::max(0.0, r.kinetic) + r.contact + r.height) + r.floor;
  return r;
}

double energy_speed_limit(const EnergyReference& reference, const EnergyModel& model,
                          double potential) {
  if (!(model.lightest_mass > 0.0)) return std::numeric_limits<double>::infinity();
  const double available = std::max(0.0, reference.energy() + reference.margin - potential) /
                           (1.0 - kEnergyMotionFraction);
  return kEnergySpeedSlack * model.speed_factor * std::sqrt(2.0 * available / model.lightest_mass);
}

std::string energy_error(const EnergyReference& reference, double kinetic, double potential,
                         const GuardPlace& at, const std::string& who) {
  // Energy beyond the float range (an infinity, a NaN) is an error whatever the margin says.
  const double energy = kinetic + potential;
  if (std::isfinite(energy) && energy <= reference.limit(kinetic)) return {};
  return fmt::format(
      "energy out of bounds at step {} (t = {:.6g} s): the scene's kinetic + potential energy is "
      "{:.6g} J ({:.4g} J kinetic), {:.4g} J above the {:.6g} J it had at step {} (t = {:.6g} s; "
      "{:.4g} J of that stored in contacts), more than the margin of {:.4g} J ({} x the {:.4g} J "
      "of motion, contacts and height the scene had, plus {:.4g} J); {}; the run has gone "
      "unstable and is making energy (dt {:.4g} s at substeps {} too large for the contact "
      "stiffness, or a contact solver that adds energy?)",
      at.step, at.time, energy, kinetic, energy - reference.energy(), reference.energy(),
      reference.step, reference.time, reference.contact, reference.margin, kEnergyMarginFraction,
      std::max(0.0, reference.kinetic) + reference.contact + reference.height, reference.floor, who,
      at.dt, at.substeps);
}

std::string energy_speed_error(const EnergyReference& reference, const EnergyModel& model,
                               double potential, double speed, double limit, std::uint32_t particle,
                               std::uint32_t body, const std::string& name, const GuardPlace& at) {
  if (!(speed > limit)) return {};
  // The energy holds, so no item has more kinetic energy than the limit leaves: this particle
  // moves with energy the guard does not count.
  return fmt::format(
      "speed out of bounds at step {} (t = {:.6g} s): particle {} of body {} '{}' moves at "
      "{:.4g} m/s, faster than the {:.4g} m/s that all the kinetic energy the scene may have "
      "({:.4g} J: the {:.6g} J it had at step {} and the {:.4g} J margin, less {:.4g} J of "
      "potential energy now, over 1 - {}) could give its lightest part ({:.4g} kg, speed factor "
      "{:.3g}); the particle moves with energy the scene does not have (a static body or pinned "
      "particle moved from outside, or a particle that does not follow its body?)",
      at.step, at.time, particle, body, name, speed, limit,
      std::max(0.0, reference.energy() + reference.margin - potential) /
          (1.0 - kEnergyMotionFraction),
      reference.energy(), reference.step, reference.margin, potential, kEnergyMotionFraction,
      model.lightest_mass, model.speed_factor);
}

}  // namespace motes
