// `motes voxelize MESH`: fills a mesh with equal particles and prints what came out.
#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "motes/output.h"
#include "motes/shapes.h"

namespace motes::cli {

namespace {

// Mass properties are printed for this density (water), as the command has no material.
constexpr double kDensity = 1000.0;

struct VoxelizeArgs {
  std::string mesh;
  double diameter = 0.0;
  std::size_t count = 0;
  double scale = 1.0;
  std::string out;
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string vec(const Eigen::Vector3d& v) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g})", v.x(), v.y(), v.z());
}

void print_bounds(const char* label, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  fmt::print("{:<18}{} to {}, size {}\n", label, vec(lo), vec(hi), vec(hi - lo));
}

void run_voxelize(const VoxelizeArgs& a) {
  Result<TriangleMesh> loaded = load_mesh(a.mesh);
  if (!loaded) fail(loaded.message());
  TriangleMesh mesh = std::move(loaded).value();
  if (mesh.vertices.empty()) fail(fmt::format("{}: the mesh has no vertices", a.mesh));
  for (Eigen::Vector3d& v : mesh.vertices) v *= a.scale;

  VoxelizeOptions options;
  options.diameter = a.diameter;
  options.target_count = a.count;
  Result<ParticleSet> voxelized = voxelize(mesh, options);
  if (!voxelized) fail(voxelized.message());
  const ParticleSet& particles = voxelized.value();
  // An open or non-manifold mesh is filled by its winding number: say so, once, on stderr.
  for (const std::string& warning : particles.warnings) {
    fmt::print(stderr, "motes: warning: {}\n", warning);
  }
  if (particles.points.empty()) fail(fmt::format("{}: voxelization gave no particles", a.mesh));

  Eigen::Vector3d mesh_lo = mesh.vertices.front(), mesh_hi = mesh.vertices.front();
  for (const Eigen::Vector3d& v : mesh.vertices) {
    mesh_lo = mesh_lo.cwiseMin(v);
    mesh_hi = mesh_hi.cwiseMax(v);
  }
  const double r = particles.diameter / 2.0;
  Eigen::Vector3d lo = particles.points.front().cast<double>();
  Eigen::Vector3d hi = lo;
  for (const Eigen::Vector3f& p : particles.points) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  lo.array() -= r;
  hi.array() += r;

  const MassProperties mp = mass_properties(particles, kDensity);
  const Eigen::Matrix3d& I = mp.inertia;
  fmt::print("{:<18}{} ({} vertices, {} triangles{})\n", "mesh", a.mesh, mesh.vertices.size(),
             mesh.triangles.size(), a.scale != 1.0 ? fmt::format(", scaled by {}", a.scale) : "");
  fmt::print("{:<18}{}\n", "particles", particles.points.size());
  fmt::print("{:<18}{:.6g} m\n", "diameter", particles.diameter);
  print_bounds("mesh bounds", mesh_lo, mesh_hi);
  print_bounds("particle bounds", lo, hi);
  fmt::print("mass properties for density {} kg/m^3 (each particle fills its lattice cell):\n",
             kDensity);
  fmt::print("{:<18}{:.6g} kg ({:.6g} kg per particle)\n", "  mass", mp.mass, mp.particle_mass);
  fmt::print("{:<18}{} m\n", "  centre of mass", vec(mp.center));
  fmt::print("{:<18}[{:.6g} {:.6g} {:.6g}; {:.6g} {:.6g} {:.6g}; {:.6g} {:.6g} {:.6g}] kg m^2\n",
             "  inertia", I(0, 0), I(0, 1), I(0, 2), I(1, 0), I(1, 1), I(1, 2), I(2, 0), I(2, 1),
             I(2, 2));
  fmt::print("{:<18}{} kg m^2\n", "  principal", vec(mp.principal_moments));

  if (!a.out.empty()) {
    const Status written =
        ends_with(a.out, ".vtu")
            ? write_vtu_file(a.out, particle_set_snapshot(particles.points, particles.diameter))
            : write_points_csv(a.out, particles.points);
    if (!written) fail(written.message());
    fmt::print("{:<18}{}\n", "written to", a.out);
  }
}

}  // namespace

void add_voxelize_command(CLI::App& app) {
  auto args = std::make_shared<VoxelizeArgs>();
  CLI::App* sub =
      app.add_subcommand("voxelize", "Fill a mesh (OBJ, PLY, STL, OFF...) with equal particles");
  sub->add_option("MESH", args->mesh, "mesh file")->required();
  CLI::Option_group* size = sub->add_option_group("particle size", "exactly one of these");
  size->add_option("--diameter", args->diameter, "particle diameter (mesh units, metres)")
      ->check(finite_positive());
  size->add_option("--count", args->count, "target particle count (the diameter is chosen)")
      ->check(whole_number_of<std::size_t>(1, 100'000'000));
  size->require_option(1);
  sub->add_option("--scale", args->scale, "multiply the mesh coordinates by this first")
      ->check(finite_positive());
  sub->add_option("--out", args->out,
                  "write the particles: FILE.vtu (VTU points), any other name: CSV x,y,z");
  sub->callback([args] { run_voxelize(*args); });
}

}  // namespace motes::cli
