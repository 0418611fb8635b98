// A serial prototype of docs/fluids.md's density constraint (issue 29), outside the library and
// its tests: a tank of fluid at rest, position-based fluids in the position solver's substeps with
// shared/fluid.h's math, measured as the hydrostatic validation will measure it. It chooses the
// parameters phase 2 starts from (docs/fluids.md, "Measured with the serial prototype" and
// "Settled with the prototype", whose table gives the arguments of each run).
//
//   g++ -O2 -std=c++20 -Ishaders scripts/fluid_tank_prototype.cpp -o /tmp/fluid_tank
//   /tmp/fluid_tank SUBSTEPS SWEEPS S_CORR_K SECONDS LAYERS CFM CONTACT WALLS XSPH LENGTH
//   (PROFILE=1 in the environment adds the bulk's layers, JACOBI=1 the sweep's stability on the
//   lattice)
//
// CFM: alpha~ as a multiple of the denominator of a lattice particle at rest; CONTACT: a minimum
// distance between fluid particles, in diameters (0: none); WALLS: 1 to count the walls in the
// density (the half-space integral of poly6: fluid_plane_share), 0 not to. Differences from the
// plan: the neighbours (within 1.1 h) are found anew every substep from a hash of h-sized cells;
// the tank's five walls are planes that clamp the particles' centres half a diameter inside; no
// solids. XSPH: the viscosity c of the velocity pass (fluid_xsph_term, once a substep; 0: none).
// LENGTH: the tank's length in diameters; longer than the block (8 d), a dam break (below;
// SETTLE=seconds in the environment rests the block behind a wall first).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <unordered_map>
#include <vector>

#include "shared/fluid.h"

namespace {

using motes::shared::FluidMaterial;
using motes::shared::vec3;
using motes::shared::vec4;
namespace sh = motes::shared;

float arg(int argc, char** argv, int i, float fallback) {
  return argc > i ? std::strtof(argv[i], nullptr) : fallback;
}

}  // namespace

int main(int argc, char** argv) {
  const int substeps = static_cast<int>(arg(argc, argv, 1, 8));
  const int sweeps = static_cast<int>(arg(argc, argv, 2, 2));
  const float k_scorr = arg(argc, argv, 3, 0.0f);
  const float seconds = arg(argc, argv, 4, 2.0f);
  const int nx = 8, ny = static_cast<int>(arg(argc, argv, 5, 16)), nz = 8;
  const float cfm = arg(argc, argv, 6, 1.0f);
  const float contact = arg(argc, argv, 7, 0.0f);
  const bool walls_count = arg(argc, argv, 8, 0.0f) != 0.0f;
  const float xsph = arg(argc, argv, 9, 0.0f);
  const float d = 0.01f, h = 2.0f * d, rho0 = 1000.0f, m = rho0 * d * d * d, g = -9.81f;
  FluidMaterial f;
  f.density_h = vec4(rho0, h, m, 0.0f);
  f.s_corr = vec4(k_scorr, 4.0f, 0.2f * h, 1.0f);
  // LENGTH (10th argument, in diameters) longer than the block: a dam break (Martin and Moyce
  // 1952): the block of a = 8 d by 2 a (n^2 = 2) is released at t = 0 in a tank LENGTH d long, and
  // the front (the farthest particle's edge, x / a) is printed against T = t sqrt(2 g / a).
  const int length = std::max(nx, static_cast<int>(arg(argc, argv, 10, 0.0f)));
  const bool dam_break = length > nx;
  const float wx = static_cast<float>(length) * d, wz = static_cast<float>(nz) * d;
  std::vector<vec3> x, v, p;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        x.push_back(vec3((static_cast<float>(i) + 0.5f) * d, (static_cast<float>(j) + 0.5f) * d,
                         (static_cast<float>(k) + 0.5f) * d));
      }
    }
  }
  const std::size_t n = x.size();
  v.assign(n, vec3(0.0f));
  p = x;
  // The denominator of a lattice particle at rest: alpha~ = cfm times it.
  vec4 rest(0.0f);
  for (int a = -2; a <= 2; ++a) {
    for (int b = -2; b <= 2; ++b) {
      for (int c = -2; c <= 2; ++c) {
        const vec3 r(static_cast<float>(a) * d, static_cast<float>(b) * d,
                     static_cast<float>(c) * d);
        rest += sh::fluid_gradient_term(r, m, 1.0f / m, rho0, h);
      }
    }
  }
  const float alpha = cfm * (rest.w + sh::dot(sh::xyz(rest), sh::xyz(rest)) / m);
  if (std::getenv("JACOBI") != nullptr) {
    // The Jacobi sweep on the lattice at rest: mode k's error is multiplied by
    // 1 - mu(k) / (1 + cfm), mu(k) = |sum_r grad W(r) sin(k . r)|^2 / sum_r |grad W(r)|^2 (0 for
    // k in (pi / d) {0, 1}^3: the null modes); scanned over k in [0, pi / d]^3 (a 40^3 grid, the
    // symbol being even in each component and symmetric under their permutations). Also
    // K = d^8 sum_r |grad W(r)|^2, the rest denominator in units of m / (rho_0^2 d^8).
    double sum2 = 0.0, best = 0.0, best_k = 0.0;
    std::vector<std::pair<vec3, vec3>> terms;
    for (int a = -2; a <= 2; ++a) {
      for (int b = -2; b <= 2; ++b) {
        for (int c = -2; c <= 2; ++c) {
          const vec3 r(static_cast<float>(a), static_cast<float>(b), static_cast<float>(c));
          const vec3 gw = sh::fluid_spiky_gradient(r, 2.0f);
          sum2 += static_cast<double>(sh::dot(gw, gw));
          terms.emplace_back(r, gw);
        }
      }
    }
    const int grid = 40;
    const double kPi = std::numbers::pi;
    for (int a = 0; a <= grid; ++a) {
      for (int b = 0; b <= a; ++b) {
        for (int c = 0; c <= b; ++c) {
          const double k[3] = {kPi * a / grid, kPi * b / grid, kPi * c / grid};
          double sx = 0.0, sy = 0.0, sz = 0.0;
          for (const auto& [r, gw] : terms) {
            const double sn =
                std::sin(k[0] * static_cast<double>(r.x) + k[1] * static_cast<double>(r.y) +
                         k[2] * static_cast<double>(r.z));
            sx += sn * static_cast<double>(gw.x);
            sy += sn * static_cast<double>(gw.y);
            sz += sn * static_cast<double>(gw.z);
          }
          const double mu = (sx * sx + sy * sy + sz * sz) / sum2;
          if (mu > best) {
            best = mu;
            best_k = k[0];
          }
        }
      }
    }
    std::printf(
        "lattice at h = 2 d: K = %.4f, Jacobi's largest mu %.3f at k = (%.3f, %.3f, %.3f) "
        "/ d, stable for cfm > %.3f\n",
        sum2, best, best_k, best_k, best_k, best / 2.0 - 1.0);
  }
  // A wall's part of the density (WALLS = 1): rho_0 times poly6's share beyond the plane, and its
  // slope (shared/fluid.h, fluid_plane_share).
  std::vector<float> rho(n), lambda(n), lambda_sum(n);
  std::vector<vec3> wall_gradient(n), shift_own(n), shift_neighbours(n), shift_scorr(n);
  std::vector<std::vector<std::size_t>> near(n);
  const float hs = (1.0f / 60.0f) / static_cast<float>(substeps);
  const long total = std::lround(seconds * 60.0f) * substeps;
  const auto cell = [&](float c) { return static_cast<long long>(std::floor(c / h)) + 1000; };
  const auto key = [&](long long a, long long b, long long c) { return (a * 4096 + b) * 4096 + c; };
  const long window = std::min(total, std::lround(0.25f * 60.0f) * substeps);
  std::vector<float> lambda_mean(n, 0.0f), height_mean(n, 0.0f);
  const float a_column = static_cast<float>(nx) * d;
  const long every = std::max(1L, std::lround(0.01f * 60.0f * static_cast<float>(substeps)));
  // SETTLE (seconds, in the environment; dam break only): the block first rests that long behind
  // a wall at x = a, which is then removed (t = 0 at the removal).
  const long settle =
      dam_break && std::getenv("SETTLE") != nullptr
          ? std::lround(std::strtof(std::getenv("SETTLE"), nullptr) * 60.0f) * substeps
          : 0;
  for (long s = -settle; s < total; ++s) {
    const float gate = s < 0 ? a_column : wx;
    if (dam_break && s >= 0 && s % every == 0) {
      // The front: the farthest particle's edge, and the 99th percentile's (a few particles
      // squeezed out ahead do not move it).
      std::vector<float> xs;
      for (const vec3& q : x) xs.push_back(q.x + 0.5f * d);
      std::sort(xs.begin(), xs.end());
      const float front = xs.back();
      const float front99 = xs[static_cast<std::size_t>(0.99 * static_cast<double>(n - 1))];
      const float t = static_cast<float>(s) * (1.0f / 60.0f) / static_cast<float>(substeps);
      std::printf("dam break: T %.3f Z %.3f (99th percentile %.3f)\n",
                  static_cast<double>(t * std::sqrt(2.0f * 9.81f / a_column)),
                  static_cast<double>(front / a_column), static_cast<double>(front99 / a_column));
    }
    for (std::size_t i = 0; i < n; ++i) {
      v[i].y += g * hs;
      p[i] = x[i] + v[i] * hs;
    }
    std::unordered_map<long long, std::vector<std::size_t>> cells;
    for (std::size_t i = 0; i < n; ++i)
      cells[key(cell(p[i].x), cell(p[i].y), cell(p[i].z))].push_back(i);
    for (std::size_t i = 0; i < n; ++i) {
      near[i].clear();
      for (int a = -1; a <= 1; ++a) {
        for (int b = -1; b <= 1; ++b) {
          for (int c = -1; c <= 1; ++c) {
            const auto it = cells.find(key(cell(p[i].x) + a, cell(p[i].y) + b, cell(p[i].z) + c));
            if (it == cells.end()) continue;
            for (std::size_t j : it->second) {
              const vec3 r = p[i] - p[j];
              if (j != i && sh::dot(r, r) < 1.21f * h * h) near[i].push_back(j);
            }
          }
        }
      }
      std::sort(near[i].begin(), near[i].end());
    }
    std::fill(lambda_sum.begin(), lambda_sum.end(), 0.0f);
    // The substep's shifts by source (the last substep's are reported): lambda_i's own terms,
    // the neighbours' lambda_j, s_corr, the wall clamps.
    std::fill(shift_own.begin(), shift_own.end(), vec3(0.0f));
    std::fill(shift_neighbours.begin(), shift_neighbours.end(), vec3(0.0f));
    std::fill(shift_scorr.begin(), shift_scorr.end(), vec3(0.0f));
    for (int it = 0; it < sweeps; ++it) {
      for (std::size_t i = 0; i < n; ++i) {
        float r = m * sh::fluid_poly6(0.0f, h);
        vec4 gathered(0.0f);
        for (std::size_t j : near[i]) {
          const vec3 rij = p[i] - p[j];
          r += m * sh::fluid_poly6(sh::dot(rij, rij), h);
          gathered += sh::fluid_gradient_term(rij, m, 1.0f / m, rho0, h);
        }
        vec3 wg(0.0f);
        if (walls_count) {
          const float dist[5] = {p[i].y, p[i].x, gate - p[i].x, p[i].z, wz - p[i].z};
          const vec3 normal[5] = {vec3(0, 1, 0), vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 0, 1),
                                  vec3(0, 0, -1)};
          for (int w = 0; w < 5; ++w) {
            r += rho0 * sh::fluid_plane_share(dist[w], h);
            wg += normal[w] * sh::fluid_plane_share_slope(dist[w], h);
          }
          gathered += vec4(wg, 0.0f);  // (1 / rho0) rho0 dF/dz n, in grad_i C_i
        }
        wall_gradient[i] = wg;
        rho[i] = r;
        lambda[i] =
            sh::fluid_lambda(sh::fluid_constraint(r, rho0, true), gathered, 1.0f / m, alpha);
        lambda_sum[i] += lambda[i];
      }
      std::vector<vec3> dp(n, vec3(0.0f));
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j : near[i]) {
          const vec3 rij = p[i] - p[j];
          const float s_corr = k_scorr > 0.0f ? sh::fluid_s_corr(sh::dot(rij, rij), m, f) : 0.0f;
          const vec3 grad = sh::fluid_spiky_gradient(rij, h);
          dp[i] += sh::fluid_shift_term(lambda[i], lambda[j], m, m, s_corr, grad, rho0);
          shift_own[i] += sh::fluid_shift_term(lambda[i], 0.0f, m, m, 0.0f, grad, rho0);
          shift_neighbours[i] += sh::fluid_shift_term(0.0f, lambda[j], m, m, 0.0f, grad, rho0);
          shift_scorr[i] += sh::fluid_shift_term(0.0f, 0.0f, m, m, s_corr, grad, rho0);
          const float c = contact * d;
          const float r2 = sh::dot(rij, rij);
          if (r2 < c * c && r2 > 0.0f) {
            const float r = std::sqrt(r2);
            dp[i] += rij * (0.125f * (c - r) / r);
          }
        }
      }
      for (std::size_t i = 0; i < n; ++i) {
        p[i] += dp[i] + wall_gradient[i] * (lambda[i] / m);
        const float r = 0.5f * d;
        p[i].y = std::max(p[i].y, r);
        p[i].x = std::clamp(p[i].x, r, gate - r);
        p[i].z = std::clamp(p[i].z, r, wz - r);
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      v[i] = (p[i] - x[i]) / hs;
      x[i] = p[i];
    }
    if (xsph > 0.0f) {
      // XSPH viscosity (fluid_xsph_term), a gather over the substep's lists from the velocities
      // before the pass (FluidVelOld in the plan).
      const std::vector<vec3> old_v = v;
      for (std::size_t i = 0; i < n; ++i) {
        vec3 dv(0.0f);
        for (std::size_t j : near[i]) {
          const vec3 rij = x[i] - x[j];
          dv += sh::fluid_xsph_term(old_v[i], old_v[j], m, rho[i], rho[j], sh::dot(rij, rij), h);
        }
        v[i] += dv * xsph;
      }
    }
    // The last quarter second's means of each particle's Lambda and height (the pressure is
    // measured on them: one substep's Lambda carries the particles' accelerations too).
    if (s >= total - window) {
      for (std::size_t i = 0; i < n; ++i) {
        lambda_mean[i] += lambda_sum[i] / static_cast<float>(window);
        height_mean[i] += x[i].y / static_cast<float>(window);
      }
    }
  }
  // The surface: the 97th percentile of the heights (a splashed particle does not move it).
  std::vector<float> heights;
  for (const vec3& q : x) heights.push_back(q.y);
  std::sort(heights.begin(), heights.end());
  const float top = heights[static_cast<std::size_t>(0.97 * static_cast<double>(n - 1))];
  const auto pressure = [&](std::size_t i) {
    return static_cast<double>(sh::fluid_pressure(lambda_mean[i], rho0, m, hs));
  };
  // Least squares of three readings of the pressure (of the last quarter second's mean Lambda,
  // against the mean depth) over the bulk: [0] the
  // Shepard-filtered p (sum_j p_j W_ij / sum_j W_ij, i included: removes the null modes, Lambda
  // alternating layer by layer or column by column, which exerts no force on a lattice and so
  // stays), [1] the raw p_i, [2] p_i (rho_i / rho_0)^2 (the reading docs/fluids.md had first).
  double sx = 0.0, sxx = 0.0, sy[3] = {0.0, 0.0, 0.0}, sxy[3] = {0.0, 0.0, 0.0};
  double sum = 0.0, worst = 0.0, myy = 0.0, own = 0.0, neighbours = 0.0, scorr = 0.0;
  double vmax = 0.0, v2 = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    vmax = std::max(vmax, static_cast<double>(sh::length(v[i])));
    v2 += static_cast<double>(sh::dot(v[i], v[i]));
    const vec3& q = x[i];
    const bool bulk =
        q.y > h && q.y < top - h && q.x > h && q.x < wx - h && q.z > h && q.z < wz - h;
    if (!bulk) continue;
    // The kernel gradient's moment in the vertical (fluid_gradient_moment_term): 1 in the
    // continuum, 0.956 on the cubic lattice at h = 2 d; the lambdas' pressure reads rho g / M_yy.
    double pw = 0.0, ww = 0.0;
    for (std::size_t j = 0; j <= near[i].size(); ++j) {
      const std::size_t k = j < near[i].size() ? near[i][j] : i;
      const vec3 rik = x[i] - x[k];
      myy += static_cast<double>(sh::fluid_gradient_moment_term(rik, m, rho0, h).y);
      const double w = static_cast<double>(sh::fluid_poly6(sh::dot(rik, rik), h));
      pw += w * pressure(k);
      ww += w;
    }
    own += static_cast<double>(shift_own[i].y);
    neighbours += static_cast<double>(shift_neighbours[i].y);
    scorr += static_cast<double>(shift_scorr[i].y);
    const double e = static_cast<double>(rho[i] / rho0) - 1.0;
    sum += e;
    worst = std::max(worst, std::abs(e));
    ++count;
    const double depth = static_cast<double>(top - height_mean[i]);
    const double ratio = static_cast<double>(rho[i] / rho0);
    const double reading[3] = {pw / ww, pressure(i), pressure(i) * ratio * ratio};
    sx += depth;
    sxx += depth * depth;
    for (int r = 0; r < 3; ++r) {
      sy[r] += reading[r];
      sxy[r] += depth * reading[r];
    }
  }
  const double rho_g = static_cast<double>(rho0) * 9.81;
  const double moment = myy / count;
  double slope[3];
  for (int r = 0; r < 3; ++r) {
    slope[r] = (count * sxy[r] - sx * sy[r]) / (count * sxx - sx * sx) / rho_g - 1.0;
  }
  std::printf(
      "substeps %d sweeps %d s_corr k %.3g cfm %.3g contact %.3g d walls %d xsph %.3g, %.1f s, %zu "
      "particles: bulk %d, density %+.3f%% mean, %.3f%% worst; pressure slope M_yy %.4f x "
      "filtered %+.2f%% of rho_0 g (filtered %+.2f%%, raw %+.2f%%, with rho_i^2 %+.2f%%); "
      "surface %.4f m (filled %.4f); speed rms %.4f, fastest %.4f m/s\n",
      substeps, sweeps, static_cast<double>(k_scorr), static_cast<double>(cfm),
      static_cast<double>(contact), walls_count ? 1 : 0, static_cast<double>(xsph),
      static_cast<double>(seconds), n, count, 100.0 * sum / count, 100.0 * worst, moment,
      100.0 * ((1.0 + slope[0]) * moment - 1.0), 100.0 * slope[0], 100.0 * slope[1],
      100.0 * slope[2], static_cast<double>(top),
      (static_cast<double>(ny) - 0.5) * static_cast<double>(d),
      std::sqrt(v2 / static_cast<double>(n)), vmax);
  // The bulk's force balance in the last substep: its shifts up, in g h_s^2 (1 at rest).
  const double weight = 9.81 * static_cast<double>(hs * hs) * count;
  std::printf(
      "  last substep's shifts up in the bulk, in g h_s^2: lambda_i's terms %.3f, the "
      "neighbours' lambda_j %.3f, s_corr %.3f, sum %.3f\n",
      own / weight, neighbours / weight, scorr / weight, (own + neighbours + scorr) / weight);
  if (std::getenv("PROFILE") != nullptr) {
    // Per layer (1 d bins of height) of the columns more than h from the side walls: mean
    // rho / rho_0 - 1, mean raw pressure against rho_0 g depth.
    for (int layer = 0; layer < ny + 2; ++layer) {
      double sr = 0.0, sp = 0.0, syl = 0.0;
      int c = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (static_cast<int>(std::floor(x[i].y / d)) != layer) continue;
        if (x[i].x > h && x[i].x < wx - h && x[i].z > h && x[i].z < wz - h) {
          sr += static_cast<double>(rho[i] / rho0) - 1.0;
          sp += pressure(i);
          syl += static_cast<double>(x[i].y);
          ++c;
        }
      }
      if (c == 0) continue;
      std::printf("  layer %2d: %3d at y %.4f: C %+.4f, p %7.1f Pa (rho_0 g depth %7.1f)\n", layer,
                  c, syl / c, sr / c, sp / c, rho_g * (static_cast<double>(top) - syl / c));
    }
  }
  return 0;
}
