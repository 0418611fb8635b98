// motes::Simulation: turns a Scene into device buffers and runs the step pipeline.
#include "motes/simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "contact_laws.h"
#include "shared/body_math.h"

namespace motes {

using shared::vec4;

namespace {

vec4 to_vec4(const Eigen::Vector3d& v, double w) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()),
          static_cast<float>(w)};
}

vec4 to_quat(const Eigen::Quaterniond& q) {
  return {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()),
          static_cast<float>(q.w())};
}

template <typename T>
Status write_vector(Device& d, Buffer b, const std::vector<T>& v) {
  return d.write(b, v.data(), v.size() * sizeof(T));
}

template <typename T>
Status read_vector(Device& d, Buffer b, std::vector<T>& v, std::size_t count) {
  v.resize(count);
  return d.read(b, v.data(), count * sizeof(T));
}

}  // namespace

Result<std::unique_ptr<Simulation>> Simulation::create(const Scene& scene,
                                                       std::unique_ptr<Device> device) {
  if (!device) return Status::error("Simulation::create: no device");
  std::unique_ptr<Simulation> sim(new Simulation());
  sim->device_ = std::move(device);
  if (Status s = sim->upload(scene); !s) return s;
  return sim;
}

Status Simulation::upload(const Scene& scene) {
  settings_ = scene.settings;
  if (!(settings_.dt > 0.0) || !std::isfinite(settings_.dt) || settings_.substeps < 1) {
    return Status::error(fmt::format("{}: dt must be > 0 and substeps >= 1 (dt {}, substeps {})",
                                     scene.source, settings_.dt, settings_.substeps));
  }
  if (scene.materials.empty()) return Status::error(scene.source + ": the scene has no material");

  // Count first, so an impossible size is refused before anything is allocated.
  std::uint64_t n = 0;
  double max_diameter = 0.0;
  for (const BodySpec& b : scene.bodies) {
    if (!b.shape || b.shape->points.empty()) {
      return Status::error(fmt::format("{}: body '{}' has no particles", scene.source, b.name));
    }
    n += b.shape->points.size();
    max_diameter = std::max(max_diameter, b.shape->diameter);
  }
  if (n > std::numeric_limits<std::uint32_t>::max() / 2) {
    return Status::error(
        fmt::format("{}: {} particles is more than motes supports (2^31)", scene.source, n));
  }
  sizes_.particles = static_cast<std::uint32_t>(n);
  sizes_.bodies = static_cast<std::uint32_t>(scene.bodies.size());
  sizes_.table = grid_table_size(sizes_.particles);
  sizes_.materials = static_cast<std::uint32_t>(scene.materials.size());
  sizes_.planes = static_cast<std::uint32_t>(scene.planes.size());

  std::vector<vec4> ppos, pvel, plocal, bpos, bquat, bvel, bangmom, bangvel, binertia;
  std::vector<std::uint32_t> pbody, pmat, bfirst;
  try {
    ppos.reserve(n);
    pvel.reserve(n);
    plocal.reserve(n);
    pbody.reserve(n);
    pmat.reserve(n);
  } catch (const std::bad_alloc&) {
    return Status::error(fmt::format("{}: out of host memory for {} particles", scene.source, n));
  }

  bodies_.clear();
  bodies_.reserve(scene.bodies.size());
  const ParticleSet* last_shape = nullptr;
  int last_material = -1;
  MassProperties mp;
  for (std::size_t bi = 0; bi < scene.bodies.size(); ++bi) {
    const BodySpec& spec = scene.bodies[bi];
    if (spec.material < 0 || static_cast<std::size_t>(spec.material) >= scene.materials.size()) {
      return Status::error(
          fmt::format("{}: body '{}' has no valid material", scene.source, spec.name));
    }
    const Material& mat = scene.materials[static_cast<std::size_t>(spec.material)];
    // Repeated bodies share a shape: compute its mass properties once.
    if (spec.shape.get() != last_shape || spec.material != last_material) {
      mp = mass_properties(*spec.shape, mat.density);
      last_shape = spec.shape.get();
      last_material = spec.material;
    }
    if (!(mp.mass > 0.0) || !std::isfinite(mp.mass)) {
      return Status::error(fmt::format("{}: body '{}' has no mass (density {})", scene.source,
                                       spec.name, mat.density));
    }
    const bool dynamic = spec.kind == BodyKind::Dynamic;
    // Body frame = principal axes: orientation = rotation * (principal -> shape frame).
    const Eigen::Quaterniond orient =
        (spec.rotation.normalized() * mp.principal_frame).normalized();
    const Eigen::Matrix3d to_body = mp.principal_frame.toRotationMatrix().transpose();
    const Eigen::Matrix3d rot = orient.toRotationMatrix();
    const Eigen::Vector3d inv_moments = mp.principal_moments.cwiseInverse();
    const Eigen::Vector3d omega = dynamic ? spec.angular_velocity : Eigen::Vector3d::Zero();
    const Eigen::Vector3d vel = dynamic ? spec.velocity : Eigen::Vector3d::Zero();
    const Eigen::Vector3d angmom =
        rot * mp.principal_moments.asDiagonal() * rot.transpose() * omega;

    BodyInfo info;
    info.name = spec.name;
    info.kind = spec.kind;
    info.mass = mp.mass;
    info.first_particle = static_cast<std::uint32_t>(ppos.size());
    info.particle_count = static_cast<std::uint32_t>(spec.shape->points.size());
    bodies_.push_back(info);

    bfirst.push_back(info.first_particle);
    bpos.push_back(to_vec4(spec.position, dynamic ? 1.0 / mp.mass : 0.0));
    bquat.push_back(to_quat(orient));
    bvel.push_back(to_vec4(vel, 0.0));
    bangmom.push_back(to_vec4(angmom, 0.0));
    bangvel.push_back(to_vec4(omega, 0.0));
    binertia.push_back(dynamic ? to_vec4(inv_moments, 0.0) : vec4(0.0f));

    const double radius = 0.5 * spec.shape->diameter;
    const double inv_pm = dynamic ? 1.0 / mp.particle_mass : 0.0;
    for (const Eigen::Vector3f& pt : spec.shape->points) {
      const Eigen::Vector3d local = to_body * (pt.cast<double>() - mp.center);
      plocal.push_back(to_vec4(local, 0.0));
      // Positions and velocities are recomputed on the device by particles_update below.
      ppos.push_back(to_vec4(spec.position + rot * local, radius));
      pvel.push_back(to_vec4(Eigen::Vector3d::Zero(), inv_pm));
      pbody.push_back(static_cast<std::uint32_t>(bi));
      pmat.push_back(static_cast<std::uint32_t>(spec.material));
    }
  }
  bfirst.push_back(static_cast<std::uint32_t>(ppos.size()));

  std::vector<shared::PlaneData> planes;
  for (const PlaneSpec& pl : scene.planes) {
    const Eigen::Vector3d nrm = pl.normal.normalized();
    shared::PlaneData d{};
    d.normal_offset = to_vec4(nrm, nrm.dot(pl.point));
    d.material = static_cast<std::uint32_t>(pl.material);
    planes.push_back(d);
  }
  const std::vector<shared::ContactLaw> laws = contact_law_table(scene.materials);

  params_ = shared::StepParams{};
  params_.gravity_dt = to_vec4(settings_.gravity, settings_.dt / settings_.substeps);
  params_.particle_count = sizes_.particles;
  params_.body_count = sizes_.bodies;
  params_.table_mask = sizes_.table - 1;
  params_.plane_count = sizes_.planes;
  params_.cell_size = static_cast<float>(max_diameter);
  params_.inv_cell_size = static_cast<float>(1.0 / max_diameter);
  params_.material_count = sizes_.materials;
  params_.flags = settings_.clamp_attraction ? MOTES_FLAG_CLAMP_ATTRACTION : 0u;

  Device& d = *device_;
  Status s = d.allocate(sizes_);
  if (s) s = write_vector(d, Buffer::ParticlePos, ppos);
  if (s) s = write_vector(d, Buffer::ParticleVel, pvel);
  if (s) s = write_vector(d, Buffer::ParticleLocal, plocal);
  if (s) s = write_vector(d, Buffer::ParticleBody, pbody);
  if (s) s = write_vector(d, Buffer::ParticleMaterial, pmat);
  if (s) s = write_vector(d, Buffer::BodyPos, bpos);
  if (s) s = write_vector(d, Buffer::BodyQuat, bquat);
  if (s) s = write_vector(d, Buffer::BodyVel, bvel);
  if (s) s = write_vector(d, Buffer::BodyAngMom, bangmom);
  if (s) s = write_vector(d, Buffer::BodyAngVel, bangvel);
  if (s) s = write_vector(d, Buffer::BodyInvInertia, binertia);
  if (s) s = write_vector(d, Buffer::BodyFirst, bfirst);
  if (s) s = write_vector(d, Buffer::ContactLaws, laws);
  if (s) s = write_vector(d, Buffer::Planes, planes);
  if (!s) return s;
  // Particles take their pose from the bodies with the device's own arithmetic.
  d.particles_update(params_);
  return d.synchronize();
}

Status Simulation::step(std::uint64_t count) {
  Device& d = *device_;
  for (std::uint64_t k = 0; k < count; ++k) {
    for (int sub = 0; sub < settings_.substeps; ++sub) {
      d.grid_build(params_);
      d.contacts_compute(params_);
      d.bodies_reduce(params_);
      d.bodies_integrate(params_);
      d.particles_update(params_);
    }
    ++steps_;
    time_ = static_cast<double>(steps_) * settings_.dt;
  }
  return d.synchronize();
}

Result<Snapshot> Simulation::snapshot() {
  Snapshot s;
  s.time = time_;
  s.step = steps_;
  Device& d = *device_;
  const std::size_t n = sizes_.particles;
  const std::size_t b = sizes_.bodies;
  Status st = read_vector(d, Buffer::ParticlePos, s.particle_pos, n);
  if (st) st = read_vector(d, Buffer::ParticleVel, s.particle_vel, n);
  if (st) st = read_vector(d, Buffer::ParticleBody, s.particle_body, n);
  if (st) st = read_vector(d, Buffer::BodyPos, s.body_pos, b);
  if (st) st = read_vector(d, Buffer::BodyQuat, s.body_quat, b);
  if (st) st = read_vector(d, Buffer::BodyVel, s.body_vel, b);
  if (st) st = read_vector(d, Buffer::BodyAngMom, s.body_angmom, b);
  if (st) st = read_vector(d, Buffer::BodyAngVel, s.body_angvel, b);
  if (!st) return st;
  return s;
}

namespace {

template <typename T>
void fnv1a(std::uint64_t& h, const std::vector<T>& v) {
  const auto* p = reinterpret_cast<const unsigned char*>(v.data());
  for (std::size_t i = 0; i < v.size() * sizeof(T); ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
}

bool finite(const vec4& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

}  // namespace

Result<std::uint64_t> Simulation::state_hash() {
  Result<Snapshot> s = snapshot();
  if (!s) return s.status();
  std::uint64_t h = 14695981039346656037ull;
  fnv1a(h, s->particle_pos);
  fnv1a(h, s->particle_vel);
  fnv1a(h, s->body_pos);
  fnv1a(h, s->body_quat);
  fnv1a(h, s->body_vel);
  fnv1a(h, s->body_angmom);
  return h;
}

Status Simulation::check_finite() {
  Result<Snapshot> s = snapshot();
  if (!s) return s.status();
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const bool ok = finite(s->body_pos[b]) && finite(s->body_quat[b]) && finite(s->body_vel[b]) &&
                    finite(s->body_angmom[b]);
    std::uint32_t bad_particle = std::numeric_limits<std::uint32_t>::max();
    const BodyInfo& info = bodies_[b];
    for (std::uint32_t i = info.first_particle; i < info.first_particle + info.particle_count;
         ++i) {
      if (!finite(s->particle_pos[i]) || !finite(s->particle_vel[i])) {
        bad_particle = i;
        break;
      }
    }
    if (!ok || bad_particle != std::numeric_limits<std::uint32_t>::max()) {
      const vec4 p = s->body_pos[b];
      return Status::error(fmt::format(
          "non-finite state at step {} (t = {} s): body {} '{}' position ({}, {}, {}){}; the "
          "time step is probably too large for the contact stiffness",
          steps_, time_, b, info.name, p.x, p.y, p.z,
          bad_particle == std::numeric_limits<std::uint32_t>::max()
              ? std::string()
              : fmt::format(", particle {}", bad_particle)));
    }
  }
  return Status::ok();
}

}  // namespace motes
