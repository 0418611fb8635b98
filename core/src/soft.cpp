// Shape-matching clusters of soft bodies, built once on the host (motes/soft.h).
#include "motes/soft.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace motes {

namespace {

/// The 9 rest terms of an offset q: q, then q_x^2, q_y^2, q_z^2, q_x q_y, q_y q_z, q_z q_x.
Eigen::Matrix<double, 9, 1> rest_terms(const Eigen::Vector3d& q) {
  Eigen::Matrix<double, 9, 1> t;
  t << q.x(), q.y(), q.z(), q.x() * q.x(), q.y() * q.y(), q.z() * q.z(), q.x() * q.y(),
      q.y() * q.z(), q.z() * q.x();
  return t;
}

/// Pseudo-inverse of a symmetric positive semi-definite matrix: eigenvalues below 1e-9 of the
/// largest count as zero (a flat or line-like rest shape has no extent to fit along them).
template <int D>
Eigen::Matrix<double, D, D> pseudo_inverse(const Eigen::Matrix<double, D, D>& a) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> eig(a);
  const auto& values = eig.eigenvalues();
  const double largest = values.cwiseAbs().maxCoeff();
  Eigen::Matrix<double, D, 1> inv = Eigen::Matrix<double, D, 1>::Zero();
  for (int k = 0; k < D; ++k) {
    if (largest > 0.0 && values[k] > 1.0e-9 * largest) inv[k] = 1.0 / values[k];
  }
  return eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

Status add_soft_body(const SoftSpec& spec, const std::vector<Eigen::Vector3d>& points,
                     double particle_mass, double substep, std::uint32_t first_particle,
                     SoftClusters& out) {
  if (!(spec.damping >= 0.0) || !std::isfinite(spec.damping)) {
    return Status::error(fmt::format("soft damping must be >= 0 (1/s), got {}", spec.damping));
  }
  if (!(spec.stiffness > 0.0 && spec.stiffness <= 1.0)) {
    return Status::error(fmt::format("soft stiffness must be in (0, 1], got {}", spec.stiffness));
  }
  if (!(spec.beta >= 0.0 && spec.beta <= 1.0)) {
    return Status::error(fmt::format("soft beta must be in [0, 1], got {}", spec.beta));
  }
  if (spec.clusters[0] < 1 || spec.clusters[1] < 1 || spec.clusters[2] < 1) {
    return Status::error("soft clusters must be at least 1 along each axis");
  }
  if (points.empty()) return Status::error("a soft body needs at least one particle");
  if (!(particle_mass > 0.0)) return Status::error("a soft body's particles need a mass");

  // Cells of the bounding box, each grown by half a cell on every side.
  Eigen::Vector3d lo = points[0];
  Eigen::Vector3d hi = points[0];
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d extent = hi - lo;
  std::vector<std::vector<std::uint32_t>> cells;
  for (int cz = 0; cz < spec.clusters[2]; ++cz) {
    for (int cy = 0; cy < spec.clusters[1]; ++cy) {
      for (int cx = 0; cx < spec.clusters[0]; ++cx) {
        const int c[3] = {cx, cy, cz};
        Eigen::Vector3d from;
        Eigen::Vector3d to;
        for (int a = 0; a < 3; ++a) {
          const double h = extent[a] / spec.clusters[a];
          const double grow = spec.clusters[a] > 1 ? 0.5 * h : 0.0;
          from[a] = lo[a] + c[a] * h - grow - 1.0e-9 * (1.0 + extent[a]);
          to[a] = lo[a] + (c[a] + 1) * h + grow + 1.0e-9 * (1.0 + extent[a]);
        }
        std::vector<std::uint32_t> cell;
        for (std::uint32_t k = 0; k < points.size(); ++k) {
          const Eigen::Vector3d& p = points[k];
          if ((p.array() >= from.array()).all() && (p.array() <= to.array()).all()) {
            cell.push_back(k);
          }
        }
        if (!cell.empty()) cells.push_back(std::move(cell));
      }
    }
  }
  std::vector<int> holders(points.size(), 0);
  for (const auto& cell : cells) {
    for (const std::uint32_t k : cell) ++holders[k];
  }

  const std::size_t particle_base = out.of_particle.size();
  out.of_particle.resize(particle_base + points.size());
  const bool quadratic = spec.mode == SoftMode::Quadratic;
  for (const auto& cell : cells) {
    const auto cluster_index = static_cast<std::uint32_t>(out.clusters.size());
    double mass = 0.0;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const std::uint32_t k : cell) {
      const double m = particle_mass / holders[k];
      mass += m;
      mean += m * points[k];
    }
    mean /= mass;
    std::vector<Eigen::Matrix<double, 9, 1>> terms;
    Eigen::Matrix<double, 9, 1> term_mean = Eigen::Matrix<double, 9, 1>::Zero();
    for (const std::uint32_t k : cell) {
      terms.push_back(rest_terms(points[k] - mean));
      term_mean += (particle_mass / holders[k]) * terms.back();
    }
    term_mean /= mass;
    Eigen::Matrix3d aqq = Eigen::Matrix3d::Zero();
    Eigen::Matrix<double, 9, 9> aqq9 = Eigen::Matrix<double, 9, 9>::Zero();
    shared::Cluster cl{};
    cl.first = static_cast<std::uint32_t>(out.members.size());
    cl.count = static_cast<std::uint32_t>(cell.size());
    cl.mode = spec.mode == SoftMode::Rigid    ? MOTES_CLUSTER_RIGID
              : spec.mode == SoftMode::Linear ? MOTES_CLUSTER_LINEAR
                                              : MOTES_CLUSTER_QUADRATIC;
    cl.alpha = static_cast<float>(spec.stiffness);
    cl.beta = spec.mode == SoftMode::Rigid ? 0.0f : static_cast<float>(spec.beta);
    cl.damping = static_cast<float>(-std::expm1(-spec.damping * substep));
    for (std::size_t j = 0; j < cell.size(); ++j) {
      const std::uint32_t k = cell[j];
      const double m = particle_mass / holders[k];
      Eigen::Matrix<double, 9, 1> t = terms[j];
      t.tail<6>() -= term_mean.tail<6>();  // the linear terms' mean is already 0
      if (!quadratic) t.tail<6>().setZero();
      aqq += m * t.head<3>() * t.head<3>().transpose();
      aqq9 += m * t * t.transpose();
      shared::ClusterMember member{};
      member.particle = first_particle + k;
      member.cluster = cluster_index;
      member.mass = static_cast<float>(m);
      for (int a = 0; a < 9; ++a) member.q[a] = static_cast<float>(t[a]);
      out.of_particle[particle_base + k].push_back(static_cast<std::uint32_t>(out.members.size()));
      out.members.push_back(member);
    }
    if (quadratic) {
      const Eigen::Matrix<double, 9, 9> inv = pseudo_inverse<9>(aqq9);
      for (int j = 0; j < 9; ++j) {
        for (int k = 0; k < 9; ++k) cl.rest[9 * j + k] = static_cast<float>(inv(k, j));
      }
    } else {
      const Eigen::Matrix3d inv = pseudo_inverse<3>(aqq);
      for (int j = 0; j < 3; ++j) {
        for (int k = 0; k < 3; ++k) cl.rest[3 * j + k] = static_cast<float>(inv(k, j));
      }
    }
    out.clusters.push_back(cl);
  }
  return Status::ok();
}

std::vector<std::uint32_t> cluster_gather(const SoftClusters& soft) {
  const std::size_t n = soft.of_particle.size();
  std::vector<std::uint32_t> gather(n + 1);
  auto at = static_cast<std::uint32_t>(n + 1);
  for (std::size_t k = 0; k < n; ++k) {
    gather[k] = at;
    at += static_cast<std::uint32_t>(soft.of_particle[k].size());
  }
  gather[n] = at;
  for (const auto& list : soft.of_particle) gather.insert(gather.end(), list.begin(), list.end());
  return gather;
}

}  // namespace motes
