// A serial prototype of docs/fluids.md's density constraint (issue 29), outside the library and
// its tests: a tank of fluid at rest, position-based fluids in the position solver's substeps with
// shared/fluid.h's math, measured as the hydrostatic validation will measure it. It chooses the
// parameters phase 2 starts from (docs/fluids.md, "Measured with the serial prototype").
//
//   g++ -O2 -std=c++20 -Ishaders scripts/fluid_tank_prototype.cpp -o /tmp/fluid_tank
//   /tmp/fluid_tank SUBSTEPS SWEEPS S_CORR_K SECONDS LAYERS CFM CONTACT WALLS
//
// CFM: alpha~ as a multiple of the denominator of a lattice particle at rest; CONTACT: a minimum
// distance between fluid particles, in diameters (0: none); WALLS: 1 to count the walls in the
// density (the half-space integral of poly6: fluid_plane_share), 0 not to. Differences from the
// plan: the neighbours (within 1.1 h) are found anew every substep from a hash of h-sized cells;
// the tank's five walls are planes that clamp the particles' centres half a diameter inside; no
// solids.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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
  const float d = 0.01f, h = 2.0f * d, rho0 = 1000.0f, m = rho0 * d * d * d, g = -9.81f;
  FluidMaterial f;
  f.density_h = vec4(rho0, h, m, 0.0f);
  f.s_corr = vec4(k_scorr, 4.0f, 0.2f * h, 1.0f);
  const float wx = static_cast<float>(nx) * d, wz = static_cast<float>(nz) * d;
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
  // A wall's part of the density (WALLS = 1): rho_0 times poly6's share beyond the plane, and its
  // slope (shared/fluid.h, fluid_plane_share).
  std::vector<float> rho(n), lambda(n), lambda_sum(n);
  std::vector<vec3> wall_gradient(n);
  std::vector<std::vector<std::size_t>> near(n);
  const float hs = (1.0f / 60.0f) / static_cast<float>(substeps);
  const long total = std::lround(seconds * 60.0f) * substeps;
  const auto cell = [&](float c) { return static_cast<long long>(std::floor(c / h)) + 1000; };
  const auto key = [&](long long a, long long b, long long c) { return (a * 4096 + b) * 4096 + c; };
  for (long s = 0; s < total; ++s) {
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
          const float dist[5] = {p[i].y, p[i].x, wx - p[i].x, p[i].z, wz - p[i].z};
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
          dp[i] += sh::fluid_shift_term(lambda[i], lambda[j], m, m, s_corr,
                                        sh::fluid_spiky_gradient(rij, h), rho0);
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
        p[i].x = std::clamp(p[i].x, r, wx - r);
        p[i].z = std::clamp(p[i].z, r, wz - r);
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      v[i] = (p[i] - x[i]) / hs;
      x[i] = p[i];
    }
  }
  // The surface: the 97th percentile of the heights (a splashed particle does not move it).
  std::vector<float> heights;
  for (const vec3& q : x) heights.push_back(q.y);
  std::sort(heights.begin(), heights.end());
  const float top = heights[static_cast<std::size_t>(0.97 * static_cast<double>(n - 1))];
  double sum = 0.0, worst = 0.0, vmax = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    vmax = std::max(vmax, static_cast<double>(sh::length(v[i])));
    const vec3& q = x[i];
    const bool bulk =
        q.y > h && q.y < top - h && q.x > h && q.x < wx - h && q.z > h && q.z < wz - h;
    if (!bulk) continue;
    const double e = static_cast<double>(rho[i] / rho0) - 1.0;
    sum += e;
    worst = std::max(worst, std::abs(e));
    ++count;
    const double depth = static_cast<double>(top - q.y);
    const double pressure =
        static_cast<double>(sh::fluid_pressure(lambda_sum[i], rho[i], rho0, m, hs));
    sx += depth;
    sy += pressure;
    sxx += depth * depth;
    sxy += depth * pressure;
  }
  const double slope = (count * sxy - sx * sy) / (count * sxx - sx * sx);
  const double rho_g = static_cast<double>(rho0) * 9.81;
  std::printf(
      "substeps %d sweeps %d s_corr k %.3g cfm %.3g contact %.3g d, %.1f s, %zu particles: bulk "
      "%d, "
      "density %+.3f%% mean, %.3f%% worst; pressure slope %.0f Pa/m (rho g %+.2f%%); surface "
      "%.4f m (filled %.4f); fastest %.4f m/s\n",
      substeps, sweeps, static_cast<double>(k_scorr), static_cast<double>(cfm),
      static_cast<double>(contact), static_cast<double>(seconds), n, count, 100.0 * sum / count,
      100.0 * worst, slope, 100.0 * (slope / rho_g - 1.0), static_cast<double>(top),
      (static_cast<double>(ny) - 0.5) * static_cast<double>(d), vmax);
  return 0;
}
