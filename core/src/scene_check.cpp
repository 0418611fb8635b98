// Scene checks on the whole scene: the explicit stability limit of the contact law, for rigid
// bodies, cloth and ropes.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "contact_laws.h"
#include "motes/cloth.h"
#include "scene_parts.h"

namespace motes::scene_detail {

namespace {

/// Dynamic bodies, cloth and ropes whose particles behave alike in a contact: same material and
/// particle mass.
struct BodyClass {
  int material = 0;
  double particle_mass = 0.0;
  std::size_t copies = 0;
  std::string name;      ///< first body of the class, for messages: body "NAME", cloth "NAME"...
  bool self = false;     ///< a cloth or rope of the class can touch itself
  bool impulse = false;  ///< rigid bodies of an impulse scene: no force among themselves
};

/// The worst contact found so far.
struct Limit {
  double h = std::numeric_limits<double>::infinity();
  std::string what;
};

/// Largest stable step of semi-implicit Euler on a contact of effective mass m_eff:
/// x'' = -w0^2 x - gamma_n x' is stable iff (w0 h)^2 + 2 gamma_n h < 4, and the tangential
/// dashpot v' = -gamma_t v iff gamma_t h < 2.
double stable_step(const shared::ContactLaw& law, double m_eff) {
  const double k = static_cast<double>(law.stiffness);
  const double gn = static_cast<double>(law.damping);
  const double gt = static_cast<double>(law.tangential);
  const double w2 = k / m_eff;
  double h = (-gn + std::sqrt(gn * gn + 4.0 * w2)) / w2;
  if (gt > 0.0) h = std::min(h, 2.0 / gt);
  return h;
}

}  // namespace

void check_initial_speed(const Node& entry, const std::string& what, const Eigen::Vector3d& v,
                         const Eigen::Vector3d& w, double reach, double diameter,
                         const Settings& settings) {
  const double speed = v.norm() + w.norm() * reach;
  const double h = settings.dt / settings.substeps;
  const double allowed = kMaxStartTravel * 0.5 * diameter;  // metres per substep
  if (speed * h <= allowed) return;
  const char* key = w.norm() * reach > v.norm() ? "angular_velocity" : "velocity";
  const Node where = entry.has(key) ? entry.at(key) : entry;
  const double safe_speed = allowed / h;
  const double safe_dt = allowed / speed * settings.substeps;
  const double substeps = std::ceil(speed * settings.dt / allowed);
  where.fail(fmt::format(
      "{} starts too fast for this dt: {:.4g} m/s at its fastest particle (|v| = {:.4g} m/s{}) "
      "would move {:.4g} m in the first substep of {:.4g} s (dt {:.4g} s / substeps {}), more "
      "than half its particle radius ({:.4g} m), so its contacts would be missed; the largest "
      "safe speed at this dt is {:.4g} m/s, the largest safe dt at this speed {:.4g} s at "
      "substeps {}{}",
      what, speed, v.norm(),
      w.isZero(0.0) ? std::string()
                    : fmt::format(", |w| = {:.4g} rad/s at {:.4g} m from its centre of mass",
                                  w.norm(), reach),
      speed * h, h, settings.dt, settings.substeps, allowed, safe_speed, safe_dt, settings.substeps,
      substeps <= 1e9 ? fmt::format(" (or keep dt and use substeps >= {:.0f})", substeps)
                      : std::string()));
}

void check_stability(const Scene& scene, const std::vector<BodyEntry>& entries) {
  // Position contacts have no force law anywhere (shared/position.h, shared/particle_shift.h):
  // nothing bounds the step but the motion guard's travel per substep.
  if (scene.settings.contact_model == ContactModel::Positions) return;
  std::map<std::pair<int, double>, BodyClass> dynamic;
  // Material of static bodies, planes and pinned cloth or rope particles -> first user.
  std::map<int, std::string> partners;
  // With impulse contacts (docs/architecture.md, "Impulse contacts"), rigid bodies meet static
  // bodies, planes and each other without the force law: those pairs have no stability limit.
  const bool impulses = rigid_contacts_without_forces(scene.settings.contact_model);
  std::map<int, std::string> rigid_partners;  // static bodies and planes
  for (const BodyEntry& e : entries) {
    const BodySpec& b = scene.bodies[e.first];
    const Material& mat = scene.materials[static_cast<std::size_t>(b.material)];
    if (b.kind == BodyKind::Static) {
      rigid_partners.emplace(b.material, fmt::format("static body \"{}\"", b.name));
      continue;
    }
    const double d = b.shape->diameter;
    const double m = mat.density * d * d * d;
    const bool impulse = impulses && !b.soft;
    // Impulse bodies form their own classes (a negative mass key), apart from soft bodies.
    BodyClass& c = dynamic[{b.material, impulse ? -m : m}];
    if (c.copies == 0) {
      c = BodyClass{b.material, m, 0, fmt::format("body \"{}\"", b.name), false, impulse};
    }
    c.copies += e.copies;
  }
  // Cloth and rope particles are lone spheres; they touch their own object beyond two lattice
  // steps (so once a side has more than 3 particles), and a pinned one is static.
  for (const LinkedSpec& l : scene.linked) {
    const Material& mat = scene.materials[static_cast<std::size_t>(l.material)];
    const char* kind = l.kind == LinkedKind::Cloth ? "cloth" : "rope";
    const std::string name = fmt::format("{} \"{}\"", kind, l.name);
    if (!l.pinned.empty()) partners.emplace(l.material, "a pinned particle of " + name);
    const double m = linked_particle_mass(mat.density, l.diameter);
    BodyClass& c = dynamic[{l.material, m}];
    if (c.copies == 0) c = BodyClass{l.material, m, 0, name};
    c.copies += 1;
    std::uint32_t side = 0;
    for (const auto& uv : l.lattice) side = std::max({side, uv[0] + 1, uv[1] + 1});
    c.self = c.self || side > 3;
  }
  for (const PlaneSpec& p : scene.planes) {
    rigid_partners.emplace(p.material, fmt::format("plane \"{}\"", p.name));
  }

  const std::vector<shared::ContactLaw> laws = contact_law_table(scene.materials);
  const std::size_t count = scene.materials.size();
  const auto law = [&](int a, int b) {
    return laws[static_cast<std::size_t>(a) * count + static_cast<std::size_t>(b)];
  };
  Limit worst;
  const auto consider = [&](const BodyClass& a, int other_material, double m_eff,
                            const std::string& other) {
    const shared::ContactLaw l = law(a.material, other_material);
    const double h = stable_step(l, m_eff);
    if (h < worst.h) {
      worst.h = h;
      worst.what = fmt::format(
          "{} (material \"{}\", particle mass {:.4g} kg) against {} (material \"{}\"): "
          "k = {:.4g} N/m, damping = {:.4g} 1/s, tangential = {:.4g} 1/s, m* = {:.4g} kg, "
          "w0 = {:.4g} rad/s",
          a.name, scene.materials[static_cast<std::size_t>(a.material)].name, a.particle_mass,
          other, scene.materials[static_cast<std::size_t>(other_material)].name,
          static_cast<double>(l.stiffness), static_cast<double>(l.damping),
          static_cast<double>(l.tangential), m_eff,
          std::sqrt(static_cast<double>(l.stiffness) / m_eff));
    }
  };
  for (const auto& [key_a, a] : dynamic) {
    for (const auto& [material, name] : partners) consider(a, material, a.particle_mass, name);
    if (!a.impulse) {
      for (const auto& [material, name] : rigid_partners) {
        consider(a, material, a.particle_mass, name);
      }
    }
    for (const auto& [key_b, b] : dynamic) {
      if (a.impulse && b.impulse) continue;
      // A body does not touch itself: a class meets itself only through a second copy, or a
      // cloth or rope through itself.
      if (key_a == key_b && a.copies < 2 && !a.self) continue;
      const double m_eff = a.particle_mass * b.particle_mass / (a.particle_mass + b.particle_mass);
      consider(a, b.material, m_eff, b.name);
    }
  }

  const Settings& s = scene.settings;
  const double h = s.dt / s.substeps;
  if (h < worst.h) return;
  const double largest_dt = worst.h * s.substeps;
  const double needed_substeps = std::floor(s.dt / worst.h) + 1.0;
  static const Json none;
  Node(none, "/settings/dt", scene.source)
      .fail(fmt::format(
          "unstable: a substep of {:.4g} s (dt {:.4g} s / substeps {}) is not below the explicit "
          "stability limit {:.4g} s of the contact of {}; the largest stable dt is just under "
          "{:.4g} s at "
          "substeps {} (or keep dt and use substeps >= {:.0f})",
          h, s.dt, s.substeps, worst.h, worst.what, largest_dt, s.substeps, needed_substeps));
}

}  // namespace motes::scene_detail
