// Helpers for the physics validation tests: scenes built in code (never from JSON) and
// conversions from the device's float vec4 layout to Eigen doubles.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "motes/backend/device.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/shapes.h"
#include "motes/simulation.h"
#include "motes/status.h"
#include "sanitized_build.h"
#include "shared/common.h"

namespace motes_test {

/// How many of a seeded test's seeds run: all of them, or in the sanitizer build
/// (tests/sanitized_build.h) the first `sanitized`. The first seed already takes the code paths;
/// the physics of every seed is checked in the first stage (a 10 s column took 83 s under the
/// sanitizers).
inline std::uint32_t seeds_to_run(std::uint32_t all, std::uint32_t sanitized = 1) {
  return sanitized_or(all, sanitized);
}

/// How many frames a long unseeded test steps: all of them, or in the sanitizer build its first
/// `sanitized`, where it checks nothing but the paths (the physics is checked in the first stage,
/// as seeds_to_run's); `physics_checked()` says which.
inline int frames_to_run(int all, int sanitized) { return sanitized_or(all, sanitized); }
inline bool physics_checked() { return !kSanitized; }

/// xyz of a device vec4, widened to double.
inline Eigen::Vector3d to_vec3(const motes::shared::vec4& v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
}

/// A device quaternion (x, y, z, w) as an Eigen quaternion (body frame to world).
inline Eigen::Quaterniond to_quat(const motes::shared::vec4& q) {
  return Eigen::Quaterniond(static_cast<double>(q.w), static_cast<double>(q.x),
                            static_cast<double>(q.y), static_cast<double>(q.z));
}

/// The value a double parameter has once the device stores it as a float.
inline double as_float(double x) { return static_cast<double>(static_cast<float>(x)); }

/// One particle of diameter d at the shape origin: a free sphere.
inline std::shared_ptr<const motes::ParticleSet> single_particle(double diameter) {
  auto set = std::make_shared<motes::ParticleSet>();
  set->points.emplace_back(0.0f, 0.0f, 0.0f);
  set->diameter = diameter;
  return set;
}

/// A box lattice of nx*ny*nz particles (motes::box_lattice); empty pointer on error.
inline std::shared_ptr<const motes::ParticleSet> lattice(int nx, int ny, int nz, double diameter) {
  motes::Result<motes::ParticleSet> r = motes::box_lattice(Eigen::Vector3i(nx, ny, nz), diameter);
  if (!r) return nullptr;
  return std::make_shared<motes::ParticleSet>(std::move(r).value());
}

inline motes::Material material(double density, double stiffness, double damping, double tangential,
                                double friction) {
  motes::Material m;
  m.name = "test";
  m.density = density;
  m.stiffness = stiffness;
  m.damping = damping;
  m.tangential = tangential;
  m.friction = friction;
  return m;
}

/// A scene with one material and no bodies yet.
inline motes::Scene scene_with(double dt, const Eigen::Vector3d& gravity,
                               const motes::Material& mat, bool clamp_attraction = false) {
  motes::Scene s;
  s.source = "<physics test>";
  s.settings.dt = dt;
  s.settings.substeps = 1;
  s.settings.gravity = gravity;
  s.settings.clamp_attraction = clamp_attraction;
  s.settings.contact = mat;
  s.materials.push_back(mat);
  return s;
}

inline motes::BodySpec body(std::shared_ptr<const motes::ParticleSet> shape,
                            const Eigen::Vector3d& position,
                            const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero(),
                            const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero(),
                            const Eigen::Quaterniond& rotation = Eigen::Quaterniond::Identity()) {
  motes::BodySpec b;
  b.name = "body";
  b.shape = std::move(shape);
  b.position = position;
  b.velocity = velocity;
  b.angular_velocity = angular_velocity;
  b.rotation = rotation;
  return b;
}

inline motes::PlaneSpec plane(const Eigen::Vector3d& normal, const Eigen::Vector3d& point) {
  motes::PlaneSpec p;
  p.name = "plane";
  p.normal = normal.normalized();
  p.point = point;
  return p;
}

/// Simulation of a scene on the OpenMP device. One thread by default: these scenes have a few
/// hundred particles, where forking threads every kernel costs more than it gains (and much more
/// on a loaded machine); test_determinism.cpp proves the state is bitwise the same at any count.
inline motes::Result<std::unique_ptr<motes::Simulation>> simulate(const motes::Scene& scene,
                                                                  int threads = 1) {
  motes::DeviceOptions options;
  options.cpu_threads = threads;
  motes::Result<std::unique_ptr<motes::Device>> device = motes::open_device("openmp", -1, options);
  if (!device) return device.status();
  return motes::Simulation::create(scene, std::move(device).value());
}

/// Reads a whole device buffer of vec4 elements (e.g. BodyInvInertia, ParticleForce).
inline motes::Result<std::vector<motes::shared::vec4>> read_vec4(motes::Simulation& sim,
                                                                 motes::Buffer b) {
  const motes::BufferLayout layout = motes::buffer_layout(b, sim.sizes());
  std::vector<motes::shared::vec4> out(layout.count);
  motes::Status st = sim.device().read(b, out.data(), layout.bytes());
  if (!st) return st;
  return out;
}

/// Kinetic energy (translation + rotation) of every dynamic body: 1/2 m v^2 + 1/2 L.w.
inline double kinetic_energy(const motes::Snapshot& s) {
  double e = 0.0;
  for (std::size_t b = 0; b < s.body_pos.size(); ++b) {
    const double inv_m = static_cast<double>(s.body_pos[b].w);
    if (inv_m == 0.0) continue;
    e += 0.5 * to_vec3(s.body_vel[b]).squaredNorm() / inv_m;
    e += 0.5 * to_vec3(s.body_angmom[b]).dot(to_vec3(s.body_angvel[b]));
  }
  return e;
}

/// Total linear momentum of the dynamic bodies: sum of m v.
inline Eigen::Vector3d linear_momentum(const motes::Snapshot& s) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t b = 0; b < s.body_pos.size(); ++b) {
    const double inv_m = static_cast<double>(s.body_pos[b].w);
    if (inv_m != 0.0) p += to_vec3(s.body_vel[b]) / inv_m;
  }
  return p;
}

/// A chain of n links of length L hanging in a V between two pins `span` apart at height y.
inline motes::LinkedSpec v_chain(int n, double link, double span, double y, double diameter) {
  const double angle = std::acos(span / (n * link));
  motes::LinkedSpec s;
  s.name = "chain";
  s.kind = motes::LinkedKind::Rope;
  s.diameter = diameter;
  Eigen::Vector3d x(0.0, y, 0.0);
  for (int k = 0; k <= n; ++k) {
    s.points.push_back(x);
    s.lattice.push_back({static_cast<std::uint32_t>(k), 0u});
    const double down = k < n / 2 ? -1.0 : 1.0;
    x += Eigen::Vector3d(link * std::cos(angle), down * link * std::sin(angle), 0.0);
  }
  for (int k = 0; k < n; ++k) {
    s.links.push_back({static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k + 1), 1.0});
  }
  s.pinned = {0u, static_cast<std::uint32_t>(n)};
  return s;
}

/// Sag of the exact discrete catenary: n links of length L, n - 1 equal interior masses, pins
/// `span` apart at one height (n even: the lowest point is node n / 2).
inline double catenary_sag(int n, double link, double span) {
  const auto span_for = [&](double h) {  // h = H / (m g)
    double s = 0.0;
    for (int k = 1; k <= n; ++k) s += link * std::cos(std::atan((n + 1 - 2 * k) / (2.0 * h)));
    return s;
  };
  double lo = 1e-9, hi = 1e9;
  for (int it = 0; it < 200; ++it) {
    const double mid = std::sqrt(lo * hi);
    (span_for(mid) < span ? lo : hi) = mid;
  }
  const double h = std::sqrt(lo * hi);
  double sag = 0.0;
  for (int k = 1; k <= n / 2; ++k) sag += link * std::sin(std::atan((n + 1 - 2 * k) / (2.0 * h)));
  return sag;
}

/// Total linear momentum of the particles [first, N) that can move (soft bodies, cloth, ropes):
/// sum of m v; with linear_momentum, the momentum of a scene's every moving part.
inline Eigen::Vector3d particle_momentum(const motes::Snapshot& s, std::size_t first) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t i = first; i < s.particle_vel.size(); ++i) {
    const double inv_m = static_cast<double>(s.particle_vel[i].w);
    if (inv_m != 0.0) p += to_vec3(s.particle_vel[i]) / inv_m;
  }
  return p;
}

/// Two spinning boxes of 2 cm particles (3 x 3 x 3 and a tilted 2 x 4 x 3) on a course to
/// collide within 0.15 s, added to `scene` (the momentum tests of every rigid contact model).
inline void add_colliding_boxes(motes::Scene& scene) {
  constexpr double kD = 0.02;
  auto a = lattice(3, 3, 3, kD);
  auto b = lattice(2, 4, 3, kD);
  scene.bodies.push_back(body(a, Eigen::Vector3d(-0.06, 0.0, 0.0), Eigen::Vector3d(1.0, 0.1, 0.0),
                              Eigen::Vector3d(0.0, 3.0, 5.0)));
  scene.bodies.push_back(body(
      b, Eigen::Vector3d(0.06, 0.013, 0.004), Eigen::Vector3d(-0.5, 0.0, 0.2),
      Eigen::Vector3d(4.0, 0.0, -2.0),
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 1.0, 0.0).normalized()))));
}

}  // namespace motes_test
