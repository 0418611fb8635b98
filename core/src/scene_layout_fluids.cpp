// The scene's fluids laid out for the device (scene_layout.h; docs/fluids.md, "Particles and
// buffers"): free particles [Nf, Ns), between the free spheres and the soft bodies, each its own
// body for the lists, and the FluidMaterials table; an emitter's particles parked (inverse mass 0).
#include <fmt/format.h>

#include <cmath>

#include "motes/fluid.h"
#include "scene_layout.h"

namespace motes::layout {

Status build_fluids(const Scene& scene, const SceneCounts& counts, HostLayout& out) {
  if (scene.fluids.empty()) return Status::ok();
  const double substep = scene.settings.dt / static_cast<double>(scene.settings.substeps);
  Result<std::vector<shared::FluidMaterial>> table = fluid_materials(scene, substep);
  if (!table) return table.status();
  out.fluid_materials = std::move(table.value());
  ParticleLayout& p = out.particles;
  std::uint32_t at = static_cast<std::uint32_t>(counts.body_particles - counts.soft_particles -
                                                counts.fluid_particles);
  const std::size_t first_entry = scene.bodies.size() + scene.linked.size();
  for (std::size_t fi = 0; fi < scene.fluids.size(); ++fi) {
    const FluidSpec& f = scene.fluids[fi];
    const Material& material = scene.materials[static_cast<std::size_t>(f.material)];
    const double mass = fluid_particle_mass(material, f.diameter);
    if (!(mass > 0.0) || !std::isfinite(mass)) {
      return Status::error(fmt::format("{}: fluid '{}' has no mass (diameter {}, density {})",
                                       scene.source, f.name, f.diameter, material.density));
    }
    out.device_index.push_back(at);
    out.bodies[first_entry + fi].mass = mass * static_cast<double>(f.points.size());
    if (f.emitter) {  // parked until they leave: inverse mass 0 (docs/fluids.md, "Emitters")
      EmitterRange e;
      e.entry = first_entry + fi;
      e.first = at;
      e.count = static_cast<std::uint32_t>(f.points.size());
      e.inverse_mass = static_cast<float>(1.0 / mass);
      e.radius = static_cast<float>(0.5 * f.diameter);
      e.emitter = *f.emitter;
      out.emitters.push_back(std::move(e));
    }
    for (const Eigen::Vector3d& x : f.points) {
      const std::uint32_t i = at++;
      p.pos[i] = to_vec4(x, 0.5 * f.diameter);
      p.vel[i] = to_vec4(f.velocity, f.emitter ? 0.0 : 1.0 / mass);
      // Its own body, as a free sphere's (body words past the rigid bodies, one per particle of
      // [Nr, Ns)).
      p.body[i] = out.sizes.bodies + (i - out.sizes.rigid_particles);
      p.material[i] = static_cast<std::uint32_t>(f.material);
    }
  }
  return Status::ok();
}

}  // namespace motes::layout
