// Benchmark workloads W1 "settle", W2 "dominoes", W3 "cloth", W4 "soft" and W5 "fluid"
// (docs/benchmarks.md).
#include "motes/workloads.h"

#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>

#include <fmt/format.h>

#include "motes/cloth.h"
#include "motes/fluid.h"
#include "motes/shapes.h"

namespace motes {

namespace {

/// SplitMix64: a small, fully specified generator (identical on every platform).
double uniform01(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

PlaneSpec plane(const char* name, Eigen::Vector3d normal, Eigen::Vector3d point) {
  PlaneSpec p;
  p.name = name;
  p.normal = normal;
  p.point = point;
  p.material = 0;
  return p;
}

/// The W1 scene without bodies: settings, material, floor and walls of a box lx x lz.
/// The scene's only material, also its default contact law: k = 2000 N/m, the given dashpot
/// coefficients (1/s) and a Coulomb cap of 0.5.
void add_material(Scene& scene, const char* name, double density, double damping,
                  double tangential) {
  Material m;
  m.name = name;
  m.density = density;
  m.stiffness = 2000.0;
  m.damping = damping;
  m.tangential = tangential;
  m.friction = 0.5;
  scene.materials.push_back(m);
  scene.settings.contact = m;
}

Scene settle_base(const std::string& source, double lx, double lz) {
  constexpr double d = 0.01;
  Scene scene;
  scene.source = source;
  scene.settings.dt = 2e-5;
  scene.settings.substeps = 1;
  scene.settings.gravity = {0.0, -9.81, 0.0};
  scene.settings.particle_diameter = d;
  scene.settings.duration = 1.2;
  add_material(scene, "glass", 2500.0, 50.0, 25.0);
  scene.planes.push_back(plane("floor", {0, 1, 0}, {0, 0, 0}));
  scene.planes.push_back(plane("x0", {1, 0, 0}, {0, 0, 0}));
  scene.planes.push_back(plane("x1", {-1, 0, 0}, {lx, 0, 0}));
  scene.planes.push_back(plane("z0", {0, 0, 1}, {0, 0, 0}));
  scene.planes.push_back(plane("z1", {0, 0, -1}, {0, 0, lz}));
  return scene;
}

/// A free sphere of diameter d weighing density * pi/6 d^3, as LAMMPS's spheres do.
std::shared_ptr<ParticleSet> free_sphere(double d) {
  auto sphere = std::make_shared<ParticleSet>();
  sphere->points.emplace_back(0.0f, 0.0f, 0.0f);
  sphere->diameter = d;
  sphere->particle_volume = std::numbers::pi / 6.0 * d * d * d;
  return sphere;
}

}  // namespace

Scene settle_workload(int nx, int ny, int nz, std::uint64_t seed) {
  constexpr double d = 0.01;
  const double s = 1.1 * d;
  Scene scene =
      settle_base(fmt::format("<W1 settle {}x{}x{}>", nx, ny, nz), (nx + 1) * s, (nz + 1) * s);
  const auto sphere = free_sphere(d);
  scene.bodies.reserve(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) *
                       static_cast<std::size_t>(nz));
  std::uint64_t state = seed;
  // Order i fastest, then k, then j (bottom layer first), matching LAMMPS's lattice fill.
  for (int j = 1; j <= ny; ++j) {
    for (int k = 1; k <= nz; ++k) {
      for (int i = 1; i <= nx; ++i) {
        BodySpec b;
        b.kind = BodyKind::Dynamic;
        b.shape = sphere;
        b.material = 0;
        const double ox = (2.0 * uniform01(state) - 1.0) * 0.01 * d;
        const double oy = (2.0 * uniform01(state) - 1.0) * 0.01 * d;
        const double oz = (2.0 * uniform01(state) - 1.0) * 0.01 * d;
        b.position = {i * s + ox, j * s + oy, k * s + oz};
        scene.bodies.push_back(std::move(b));
      }
    }
  }
  return scene;
}

Result<Scene> settle_workload_from_lammps(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::error(fmt::format("{}: cannot open LAMMPS data file", path));
  std::size_t atoms = 0;
  double xhi = 0.0, zhi = 0.0;
  std::map<long, std::array<double, 4>> pos;  // id -> diameter, x, y, z
  std::map<long, std::array<double, 3>> vel;
  std::string line, section;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ls(line);
    if (line.find(" atoms") != std::string::npos && atoms == 0 && section.empty()) {
      ls >> atoms;
    } else if (line.find("xlo xhi") != std::string::npos) {
      double lo = 0.0;
      ls >> lo >> xhi;
    } else if (line.find("zlo zhi") != std::string::npos) {
      double lo = 0.0;
      ls >> lo >> zhi;
    } else if (line.rfind("Atoms", 0) == 0 || line.rfind("Velocities", 0) == 0) {
      section = line.substr(0, line.find(' '));
    } else if (section == "Atoms") {
      long id = 0, type = 0;
      double diameter = 0.0, density = 0.0, x = 0.0, y = 0.0, z = 0.0;
      if (!(ls >> id >> type >> diameter >> density >> x >> y >> z)) {
        return Status::error(fmt::format(
            "{}:{}: expected 'id type diameter density x y z' (atom style sphere)", path, line_no));
      }
      pos[id] = {diameter, x, y, z};
    } else if (section == "Velocities") {
      long id = 0;
      double vx = 0.0, vy = 0.0, vz = 0.0;
      if (!(ls >> id >> vx >> vy >> vz)) {
        return Status::error(fmt::format("{}:{}: expected 'id vx vy vz ...'", path, line_no));
      }
      vel[id] = {vx, vy, vz};
    }
  }
  if (atoms == 0 || pos.size() != atoms || vel.size() != atoms || !(xhi > 0.0) || !(zhi > 0.0)) {
    return Status::error(fmt::format(
        "{}: not a W1 state: {} atoms declared, {} positions, {} velocities, box x {} z {}", path,
        atoms, pos.size(), vel.size(), xhi, zhi));
  }
  Scene scene = settle_base(fmt::format("<W1 settle from {}>", path), xhi, zhi);
  const auto sphere = free_sphere(0.01);
  scene.bodies.reserve(atoms);
  for (const auto& [id, p] : pos) {
    if (std::abs(p[0] - 0.01) > 1e-9) {
      return Status::error(
          fmt::format("{}: atom {} has diameter {}, W1 uses 0.01", path, id, p[0]));
    }
    auto v = vel.find(id);
    if (v == vel.end()) return Status::error(fmt::format("{}: atom {} has no velocity", path, id));
    BodySpec b;
    b.shape = sphere;
    b.position = {p[1], p[2], p[3]};
    b.velocity = {v->second[0], v->second[1], v->second[2]};
    scene.bodies.push_back(std::move(b));
  }
  return scene;
}

bool settle_dimensions(std::uint64_t particles, int& nx, int& ny, int& nz) {
  struct Dims {
    std::uint64_t n;
    int x, y, z;
  };
  static constexpr Dims kSizes[] = {
      {16384, 32, 16, 32},       {65536, 64, 32, 32},        {262144, 64, 64, 64},
      {1048576, 128, 64, 128},   {4194304, 256, 64, 256},    {16777216, 256, 256, 256},
      {67108864, 512, 256, 512}, {134217728, 512, 512, 512}, {268435456, 1024, 256, 1024}};
  for (const Dims& s : kSizes) {
    if (s.n == particles) {
      nx = s.x;
      ny = s.y;
      nz = s.z;
      return true;
    }
  }
  return false;
}

Scene dominoes_workload(int count, int rows) {
  constexpr double d = 0.01;
  const double height = 5 * d;
  const double pitch = 0.6 * height;
  const double row_pitch = 3 * d + 2 * d;
  Scene scene;
  scene.source = fmt::format("<W2 dominoes {} in {} rows>", count, rows);
  scene.settings.dt = 2e-5;
  scene.settings.particle_diameter = d;
  scene.settings.duration = 1.0;
  add_material(scene, "wood", 700.0, 1000.0, 500.0);

  auto domino = std::make_shared<ParticleSet>();
  domino->diameter = d;
  // 1 particle thick along the chain (x), 3 wide (z), 5 tall (y), centred at the origin.
  for (int y = 0; y < 5; ++y) {
    for (int z = 0; z < 3; ++z) {
      domino->points.emplace_back(0.0f, static_cast<float>((y - 2) * d),
                                  static_cast<float>((z - 1) * d));
    }
  }
  const int per_row = (count + rows - 1) / rows;
  scene.bodies.reserve(static_cast<std::size_t>(count));
  for (int n = 0; n < count; ++n) {
    const int row = n / per_row;
    const int col = n % per_row;
    BodySpec b;
    b.name = fmt::format("domino[{}]", n);
    b.shape = domino;
    b.material = 0;
    b.position = {col * pitch, 0.5 * height + 1e-4, row * row_pitch};
    if (col == 0) b.angular_velocity = {0.0, 0.0, -8.0};  // tips towards +x
    scene.bodies.push_back(std::move(b));
  }
  scene.planes.push_back(plane("floor", {0, 1, 0}, {0, 0, 0}));
  return scene;
}

Scene impulse_dominoes_workload(int count, int rows) {
  Scene scene = dominoes_workload(count, rows);
  scene.source = fmt::format("<impulse dominoes {} in {} rows>", count, rows);
  scene.settings.dt = 2e-4;
  scene.settings.contact_model = ContactModel::Impulses;
  scene.settings.impulse_iterations = 16;
  for (Material& m : scene.materials) m.restitution = 0.3;
  scene.settings.contact.restitution = 0.3;
  return scene;
}

Scene cloth_workload(int side) {
  constexpr double d = 0.01;
  Scene scene;
  scene.source = fmt::format("<cloth workload {} x {}>", side, side);
  scene.settings.dt = 1e-4;
  scene.settings.particle_diameter = d;
  scene.settings.duration = 1.0;
  scene.settings.constraint_iterations = 8;
  scene.settings.link_damping = 1.0;
  add_material(scene, "cloth", 1000.0, 500.0, 200.0);
  ClothOptions o;
  o.corner = {0.0, 0.1 + d * side, 0.0};
  o.edge_u = {d * (side - 1), 0.0, 0.0};
  o.edge_v = {0.0, 0.0, d * (side - 1)};
  o.nu = side;
  o.nv = side;
  o.diameter = d;
  Result<LinkedSpec> cloth = make_cloth(o);
  if (!cloth) return scene;  // the caller's side is checked: 2 <= side <= 1024
  LinkedSpec c = std::move(cloth).value();
  c.name = "cloth";
  c.pinned = {0u, static_cast<std::uint32_t>(side - 1)};
  scene.linked.push_back(std::move(c));
  scene.planes.push_back(plane("floor", {0, 1, 0}, {0, 0, 0}));
  return scene;
}

Scene soft_workload(int count) {
  constexpr double d = 0.01;
  Scene scene;
  scene.source = fmt::format("<soft workload {} cubes>", count);
  scene.settings.dt = 1e-4;
  scene.settings.particle_diameter = d;
  scene.settings.duration = 1.0;
  add_material(scene, "rubber", 1100.0, 500.0, 200.0);
  Result<ParticleSet> box = box_lattice(Eigen::Vector3i(7, 7, 8), d);
  if (!box) return scene;
  const auto shape = std::make_shared<const ParticleSet>(std::move(box).value());
  SoftSpec soft;
  soft.frequency = 20.0;
  soft.damping = 40.0;
  soft.mode = SoftMode::Linear;
  soft.beta = 0.3;
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count))));
  for (int k = 0; k < count; ++k) {
    BodySpec b;
    b.name = fmt::format("cube{}", k);
    b.shape = shape;
    b.material = 0;
    b.soft = soft;
    b.position = {0.12 * (k % side), 0.1, 0.12 * (k / side)};
    b.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * (k % 7), Eigen::Vector3d::UnitY()));
    scene.bodies.push_back(std::move(b));
  }
  scene.planes.push_back(plane("floor", {0, 1, 0}, {0, 0, 0}));
  return scene;
}

Scene fluid_workload(std::uint64_t particles) {
  constexpr double d = 0.01;
  const int a = std::max(2, static_cast<int>(std::cbrt(static_cast<double>(particles) / 2.0)));
  Scene scene;
  scene.source = fmt::format("<fluid workload {} x {} x {}>", a, 2 * a, a);
  scene.settings.dt = 1.0 / 60.0;
  scene.settings.substeps = kFluidSubsteps;
  scene.settings.fluid_iterations = kFluidIterations;
  scene.settings.neighbour_capacity = kFluidNeighbourCapacity;
  scene.settings.contact_model = ContactModel::Positions;
  scene.settings.gravity = {0.0, -9.81, 0.0};
  scene.settings.particle_diameter = d;
  scene.settings.duration = 1.0;
  Material water;
  water.name = "water";
  water.density = 1000.0;
  water.friction = 0.1;
  scene.materials.push_back(water);
  scene.settings.contact = water;
  Material wood;
  wood.name = "wood";
  wood.density = 700.0;
  wood.friction = 0.4;
  scene.materials.push_back(wood);
  const double width = a * d;
  FluidSpec f;
  f.name = "water";
  f.material = 0;
  f.diameter = d;
  f.points.reserve(static_cast<std::size_t>(2) * a * a * a);
  for (int z = 0; z < a; ++z) {
    for (int y = 0; y < 2 * a; ++y) {
      for (int x = 0; x < a; ++x)
        f.points.emplace_back((x + 0.5) * d, (y + 0.5) * d, (z + 0.5) * d);
    }
  }
  scene.fluids.push_back(std::move(f));
  Result<ParticleSet> box = box_lattice(Eigen::Vector3i(4, 4, 4), d);
  if (box) {
    const auto shape = std::make_shared<const ParticleSet>(std::move(box).value());
    for (int k = 0; k < 4; ++k) {
      BodySpec b;
      b.name = fmt::format("block{}", k);
      b.shape = shape;
      b.material = 1;
      b.position = {width * (1.5 + 0.5 * k), 0.02, width * (0.2 + 0.2 * k)};
      scene.bodies.push_back(std::move(b));
    }
  }
  scene.planes.push_back(plane("floor", {0, 1, 0}, {0, 0, 0}));
  scene.planes.push_back(plane("x0", {1, 0, 0}, {0, 0, 0}));
  scene.planes.push_back(plane("x1", {-1, 0, 0}, {4.0 * width, 0, 0}));
  scene.planes.push_back(plane("z0", {0, 0, 1}, {0, 0, 0}));
  scene.planes.push_back(plane("z1", {0, 0, -1}, {0, 0, width}));
  return scene;
}

}  // namespace motes
