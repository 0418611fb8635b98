// Mass, centre of mass and inertia tensor of a set of equal spheres.
#include <Eigen/Eigenvalues>

#include "motes/shapes.h"

namespace motes {

MassProperties mass_properties(const ParticleSet& particles, double density) {
  MassProperties out;
  const auto count = particles.points.size();
  if (count == 0) return out;  // the shape builders and the voxelizer never return an empty set
  const double d = particles.diameter;
  // By default each sphere stands for its lattice cell, so the body's mass is density x the cells'
  // volume; a set may say otherwise (a lone sphere weighs density x pi/6 d^3).
  const double volume = particles.particle_volume > 0.0 ? particles.particle_volume : d * d * d;
  out.particle_mass = density * volume;
  out.mass = out.particle_mass * static_cast<double>(count);

  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : particles.points) sum += p.cast<double>();
  out.center = sum / static_cast<double>(count);

  // Second moment about the centre (a second pass, so no large-offset cancellation).
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& p : particles.points) {
    const Eigen::Vector3d r = p.cast<double>() - out.center;
    second.noalias() += r * r.transpose();
  }
  // I = sum m (|r|^2 1 - r r^T) + sum 2/5 m (d/2)^2 1. The per-sphere term keeps the tensor
  // invertible for flat and collinear particle sets (and a single particle).
  const double sphere_term = 0.4 * out.particle_mass * 0.25 * d * d * static_cast<double>(count);
  out.inertia = out.particle_mass * (second.trace() * Eigen::Matrix3d::Identity() - second) +
                sphere_term * Eigen::Matrix3d::Identity();

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(out.inertia);
  out.principal_moments = solver.eigenvalues();  // ascending
  Eigen::Matrix3d axes = solver.eigenvectors();  // columns: principal axes in the shape frame
  if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
  out.principal_frame = Eigen::Quaterniond(axes).normalized();
  return out;
}

}  // namespace motes
