// The host side of fluid materials (motes/fluid.h; docs/fluids.md).
#include "motes/fluid.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace motes {

double fluid_rest_denominator(double rest_density, double diameter) {
  // Every lattice point within h = 2 d of a particle (|offset| < 2 in spacings), each adding
  // |grad W|^2 of the spiky kernel: (45 / (pi h^6))^2 (h - r)^4.
  const double d = diameter;
  const double h = kFluidSupportDiameters * d;
  const double c = 45.0 / (std::numbers::pi * std::pow(h, 6));
  double sum = 0.0;
  for (int x = -2; x <= 2; ++x) {
    for (int y = -2; y <= 2; ++y) {
      for (int z = -2; z <= 2; ++z) {
        const double r = d * std::sqrt(static_cast<double>(x * x + y * y + z * z));
        if (r == 0.0 || r >= h) continue;
        const double g = c * (h - r) * (h - r);
        sum += g * g;
      }
    }
  }
  const double mass = rest_density * d * d * d;
  return mass / (rest_density * rest_density) * sum;
}

double fluid_particle_mass(const Material& m, double diameter) {
  const double rho0 = m.rest_density > 0.0 ? m.rest_density : m.density;
  return rho0 * diameter * diameter * diameter;
}

shared::FluidMaterial fluid_material(const Material& m, double diameter, double substep) {
  const double rho0 = m.rest_density > 0.0 ? m.rest_density : m.density;
  const double h = kFluidSupportDiameters * diameter;
  const double mass = fluid_particle_mass(m, diameter);
  const double alpha = kFluidRelaxation * fluid_rest_denominator(rho0, diameter);
  const double k = kFluidScorrK * substep / kFluidReferenceSubstep;
  const auto f = [](double v) { return static_cast<float>(v); };
  shared::FluidMaterial out{};
  out.density_h = {f(rho0), f(h), f(mass), f(alpha)};
  out.s_corr = {f(k), f(kFluidScorrPower), f(kFluidScorrDq * h), f(kFluidSolidScale)};
  out.velocity = {f(m.viscosity), f(m.vorticity), f(m.cohesion), f(m.adhesion)};
  out.reserved = {0.0f, 0.0f, 0.0f, 0.0f};
  return out;
}

Result<std::vector<shared::FluidMaterial>> fluid_materials(const Scene& scene, double substep) {
  std::vector<shared::FluidMaterial> table(scene.materials.size(), shared::FluidMaterial{});
  std::vector<double> diameter(scene.materials.size(), 0.0);
  for (const FluidSpec& fluid : scene.fluids) {
    const auto at = static_cast<std::size_t>(fluid.material);
    if (at >= table.size()) {
      return Status::error(fmt::format("{}: fluid \"{}\": material {} does not exist", scene.source,
                                       fluid.name, fluid.material));
    }
    if (diameter[at] != 0.0 && diameter[at] != fluid.diameter) {
      return Status::error(fmt::format(
          "{}: fluid \"{}\": material \"{}\" is a fluid's of diameter {:.6g} m already, this one's "
          "is {:.6g} m (a fluid material has one particle size: give this fluid its own material)",
          scene.source, fluid.name, scene.materials[at].name, diameter[at], fluid.diameter));
    }
    diameter[at] = fluid.diameter;
    table[at] = fluid_material(scene.materials[at], fluid.diameter, substep);
  }
  return table;
}

}  // namespace motes
