// The host side of fluid materials (motes/fluid.h; docs/fluids.md).
#include "motes/fluid.h"

#include "motes/checkpoint.h"

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

namespace {

/// sum_j d^3 poly6(|x_i - x_j|, h = 2 d) over a cubic lattice of spacing `spacing` diameters.
double lattice_density(double spacing) {
  const double h = kFluidSupportDiameters;
  const double c = 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9));
  double sum = 0.0;
  for (int x = -2; x <= 2; ++x) {
    for (int y = -2; y <= 2; ++y) {
      for (int z = -2; z <= 2; ++z) {
        const double r2 = spacing * spacing * static_cast<double>(x * x + y * y + z * z);
        if (r2 < h * h) sum += c * std::pow(h * h - r2, 3);
      }
    }
  }
  return sum;
}

}  // namespace

double fluid_rest_spacing(double diameter) {
  // The sum falls with the spacing: bisect it between d (1.0098) and 1.02 d (below 1).
  static const double ratio = [] {
    double lo = 1.0, hi = 1.02;
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      (lattice_density(mid) > 1.0 ? lo : hi) = mid;
    }
    return lo;
  }();
  return ratio * diameter;
}

double fluid_s_corr_energy(double r, const shared::FluidMaterial& f, double substep, int sweeps) {
  // u(r) = int_r^h |F(s)| ds, F the pair's repulsion: each sweep moves i by
  // (s_corr / rho_0) grad W_spiky (fluid_shift_term), s_corr = -k m h^2 (W_poly6 / W_poly6(dq))^n
  // (fluid_s_corr), so |F| = sweeps (m / h_s^2) k m h^2 (W(s) / W(dq))^n / rho_0
  // x 45 / (pi h^6) (h - s)^2. Simpson's rule over 256 intervals (the integrand is a polynomial of
  // degree 3n + 2 in s).
  const double rho0 = static_cast<double>(f.density_h.x), h = static_cast<double>(f.density_h.y),
               m = static_cast<double>(f.density_h.z);
  const double k = static_cast<double>(f.s_corr.x), dq = static_cast<double>(f.s_corr.z);
  const int n = static_cast<int>(f.s_corr.y);
  if (!(r < h)) return 0.0;
  const auto poly6 = [h](double s) { return std::pow(1.0 - (s * s) / (h * h), 3); };  // / W(0)
  const double wdq = poly6(dq);
  const double scale = static_cast<double>(sweeps) * m / (substep * substep) * k * m * h * h /
                       rho0 * 45.0 / (std::numbers::pi * std::pow(h, 6));
  const auto force = [&](double s) { return std::pow(poly6(s) / wdq, n) * (h - s) * (h - s); };
  constexpr int kIntervals = 256;
  const double step = (h - r) / kIntervals;
  double sum = force(r) + force(h);
  for (int i = 1; i < kIntervals; ++i) sum += (i % 2 == 1 ? 4.0 : 2.0) * force(r + i * step);
  return scale * sum * step / 3.0;
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

std::uint64_t emitter_particles_by(const FluidEmitter& e, double t) {
  if (!(e.layer_period > 0.0) || e.nozzle.empty() || t < e.start - 1e-12) return 0;
  // Layer k leaves at start + k T; the small slack keeps a layer due at a step's start exactly.
  const double T = e.layer_period;
  double layers = std::floor((t - e.start) / T + 1e-9) + 1.0;
  if (std::isfinite(e.stop)) layers = std::min(layers, std::ceil((e.stop - e.start) / T - 1e-9));
  const double particles = std::max(0.0, layers) * static_cast<double>(e.nozzle.size());
  return particles >= static_cast<double>(e.max_particles) ? e.max_particles
                                                           : static_cast<std::uint64_t>(particles);
}

std::uint64_t particle_w_hash(std::span<const shared::vec4> pos, std::span<const shared::vec4> vel,
                              std::span<const EmitterRange> emitters) {
  std::vector<float> w(vel.size());
  for (std::size_t i = 0; i < vel.size(); ++i) w[i] = vel[i].w;
  for (const EmitterRange& e : emitters) {
    for (std::uint32_t k = 0; k < e.count && e.first + k < w.size(); ++k) {
      w[e.first + k] = e.inverse_mass;
    }
  }
  std::uint64_t h = fnv1a64(nullptr, 0);
  for (std::size_t i = 0; i < pos.size() && i < w.size(); ++i) {
    const float pair[2] = {pos[i].w, w[i]};
    h = fnv1a64(pair, sizeof pair, h);
  }
  return h;
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
