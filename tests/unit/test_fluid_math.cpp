// shaders/shared/fluid.h (issue 29, docs/fluids.md) against closed forms worked by hand: the
// kernels' normalization and derivatives, the lattice density that sets h = 2 d, the density
// constraint's lambda and correction for two particles, s_corr, pressure, and the velocity terms.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "shared/fluid.h"

namespace {

using motes::shared::FluidMaterial;
using motes::shared::vec3;
using motes::shared::vec4;
namespace sh = motes::shared;

constexpr double kPi = 3.14159265358979323846;

double D(float x) { return static_cast<double>(x); }

/// 4 pi integral of r^2 f(r) over [0, h] by Simpson's rule (n even).
template <class F>
double radial_integral(F f, double h, int n = 4000) {
  const double dr = h / n;
  double sum = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double r = k * dr;
    const double w = (k == 0 || k == n) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
    sum += w * r * r * static_cast<double>(f(r));
  }
  return 4.0 * kPi * sum * dr / 3.0;
}

FluidMaterial material(float rho0, float d) {
  FluidMaterial f;
  const float h = 2.0f * d;
  f.density_h = vec4(rho0, h, rho0 * d * d * d, 1e-9f);
  f.s_corr = vec4(0.1f, 4.0f, 0.2f * h, 1.0f);
  f.velocity = vec4(0.01f, 0.0f, 0.0f, 0.0f);
  return f;
}

TEST(FluidMath, Poly6IntegratesToOne) {
  for (const float h : {0.02f, 1.0f, 3.5f}) {
    const double total =
        radial_integral([&](double r) { return sh::fluid_poly6(static_cast<float>(r * r), h); }, h);
    EXPECT_NEAR(total, 1.0, 1e-5) << "h = " << h;
  }
}

TEST(FluidMath, SpikyIntegratesToOne) {
  for (const float h : {0.02f, 1.0f}) {
    const double total =
        radial_integral([&](double r) { return sh::fluid_spiky(static_cast<float>(r), h); }, h);
    EXPECT_NEAR(total, 1.0, 1e-5) << "h = " << h;
  }
}

TEST(FluidMath, KernelsClosedForms) {
  const float h = 0.02f;
  const double h3 = D(h) * D(h) * D(h);
  // poly6: 315 / (64 pi h^3) (1 - q^2)^3; spiky: 15 / (pi h^3) (1 - q)^3.
  EXPECT_NEAR(D(sh::fluid_poly6(0.0f, h)), 315.0 / (64.0 * kPi * h3),
              1e-6 * 315.0 / (64 * kPi * h3));
  const double q = 0.5;
  const double poly6_half = 315.0 / (64.0 * kPi * h3) * std::pow(1.0 - q * q, 3);
  EXPECT_NEAR(D(sh::fluid_poly6(0.25f * h * h, h)), poly6_half, 1e-6 * poly6_half);
  const double spiky_half = 15.0 / (kPi * h3) * std::pow(1.0 - q, 3);
  EXPECT_NEAR(D(sh::fluid_spiky(0.5f * h, h)), spiky_half, 1e-6 * spiky_half);
  EXPECT_EQ(sh::fluid_poly6(h * h, h), 0.0f);
  EXPECT_EQ(sh::fluid_spiky(h, h), 0.0f);
  EXPECT_EQ(sh::fluid_poly6(4.0f * h * h, h), 0.0f);
}

TEST(FluidMath, SpikyGradientIsTheDerivativeAlongTheSeparation) {
  const float h = 0.02f;
  const vec3 dir(0.48f, -0.6f, 0.64f);  // unit length
  for (const double q : {0.1, 0.3, 0.5, 0.77, 0.95}) {
    const double r = q * D(h);
    const double e = 1e-4 * D(h);
    // dW/dr by central differences of the kernel in double: -45 / (pi h^6) (h - r)^2.
    const auto w = [&](double s) {
      return 15.0 / (kPi * std::pow(D(h), 6)) * std::pow(D(h) - s, 3);
    };
    const double dwdr = (w(r + e) - w(r - e)) / (2.0 * e);
    const vec3 g = sh::fluid_spiky_gradient(dir * static_cast<float>(r), h);
    // The gradient of W(x_i - x_j) at r_ij = r dir is dW/dr dir: it points back towards j.
    EXPECT_NEAR(D(g.x), dwdr * D(dir.x), 1e-5 * std::abs(dwdr)) << "q = " << q;
    EXPECT_NEAR(D(g.y), dwdr * D(dir.y), 1e-5 * std::abs(dwdr)) << "q = " << q;
    EXPECT_NEAR(D(g.z), dwdr * D(dir.z), 1e-5 * std::abs(dwdr)) << "q = " << q;
    EXPECT_LT(dwdr, 0.0);
    // With respect to x_j it is the negative: the kernel is even.
    const vec3 gj = sh::fluid_spiky_gradient(dir * static_cast<float>(-r), h);
    EXPECT_EQ(gj.x, -g.x);
    EXPECT_EQ(gj.y, -g.y);
    EXPECT_EQ(gj.z, -g.z);
  }
  const vec3 zero = sh::fluid_spiky_gradient(vec3(0.0f), h);
  EXPECT_EQ(zero.x, 0.0f);
  const vec3 beyond = sh::fluid_spiky_gradient(vec3(h, 0.0f, 0.0f), h);
  EXPECT_EQ(beyond.x, 0.0f);
}

// The choice h = 2 d (docs/fluids.md): poly6 over a cubic lattice of spacing d sums to
// 315 / (64 pi 2^9) (64 + 6 x 27 + 12 x 8 + 8) = 103950 / (32768 pi) = 1.009775 of the lattice's
// own density.
TEST(FluidMath, LatticeDensityAtTwoSpacings) {
  const float d = 0.01f;
  const float rho0 = 1000.0f;
  const FluidMaterial f = material(rho0, d);
  double rho = 0.0;
  int neighbours = 0;
  for (int x = -2; x <= 2; ++x) {
    for (int y = -2; y <= 2; ++y) {
      for (int z = -2; z <= 2; ++z) {
        const vec3 r(static_cast<float>(x) * d, static_cast<float>(y) * d,
                     static_cast<float>(z) * d);
        const float w = sh::fluid_poly6(sh::dot(r, r), f.density_h.y);
        rho += D(f.density_h.z) * D(w);
        neighbours += (w > 0.0f && (x != 0 || y != 0 || z != 0)) ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(neighbours, 26);
  EXPECT_NEAR(rho / D(rho0), 103950.0 / (32768.0 * kPi), 1e-5);
}

// A plane's share of the kernel: half at the plane, none from h on, and the integral of poly6 over
// the half-space beyond the plane (by slabs: each slab at height t carries pi K (h^2 - t^2)^4 / 4,
// integrated here numerically from the kernel itself, over discs).
TEST(FluidMath, PlaneShareIsTheKernelBeyondThePlane) {
  const float h = 0.02f;
  EXPECT_NEAR(D(sh::fluid_plane_share(0.0f, h)), 0.5, 1e-6);
  EXPECT_EQ(sh::fluid_plane_share(h, h), 0.0f);
  EXPECT_EQ(sh::fluid_plane_share(2.0f * h, h), 0.0f);
  for (const double q : {0.1, 0.3, 0.5, 0.8}) {
    // Beyond the plane at distance z = q h: slabs at t in [z, h], each a disc of radius
    // sqrt(h^2 - t^2) integrated over rings of the kernel.
    const double z = q * D(h);
    const int n = 400;
    double total = 0.0;
    for (int a = 0; a < n; ++a) {
      const double t = z + (D(h) - z) * (a + 0.5) / n;
      const double rmax = std::sqrt(std::max(D(h) * D(h) - t * t, 0.0));
      double disc = 0.0;
      for (int b = 0; b < n; ++b) {
        const double rho = rmax * (b + 0.5) / n;
        disc += 2.0 * kPi * rho * D(sh::fluid_poly6(static_cast<float>(rho * rho + t * t), h)) *
                rmax / n;
      }
      total += disc * (D(h) - z) / n;
    }
    EXPECT_NEAR(D(sh::fluid_plane_share(static_cast<float>(z), h)), total, 2e-4) << "q = " << q;
    const double e = 1e-3 * D(h);
    const double slope = (D(sh::fluid_plane_share(static_cast<float>(z + e), h)) -
                          D(sh::fluid_plane_share(static_cast<float>(z - e), h))) /
                         (2.0 * e);
    EXPECT_NEAR(D(sh::fluid_plane_share_slope(static_cast<float>(z), h)), slope,
                1e-3 * std::abs(slope))
        << "q = " << q;
  }
}

TEST(FluidMath, ConstraintIsUnilateral) {
  EXPECT_EQ(sh::fluid_constraint(900.0f, 1000.0f, true), 0.0f);
  EXPECT_NEAR(sh::fluid_constraint(900.0f, 1000.0f, false), -0.1f, 1e-7f);
  EXPECT_NEAR(sh::fluid_constraint(1020.0f, 1000.0f, true), 0.02f, 1e-7f);
}

// Two fluid particles of mass m at distance r < h along x, i at the origin: by hand
// grad W_ij = g e_x (g = 45 / (pi h^6) (h - r)^2: towards j), grad_i C_i = (m / rho0) g e_x,
// grad_j C_i = -(m / rho0) g e_x, so the denominator is (1/m + 1/m) (m g / rho0)^2 =
// 2 m g^2 / rho0^2, and lambda_i = -C rho0^2 / (2 m g^2);
// dx_i = (lambda_i + lambda_j) grad W_ij / rho0.
TEST(FluidMath, LambdaAndShiftOfTwoParticles) {
  const float d = 0.01f;
  const float rho0 = 1000.0f;
  const FluidMaterial f = material(rho0, d);
  const float h = f.density_h.y;
  const float m = f.density_h.z;
  const float r = 0.6f * h;
  const vec3 rij(-r, 0.0f, 0.0f);  // x_i - x_j with j at +r on x
  const double g = 45.0 / (kPi * std::pow(D(h), 6)) * std::pow(D(h) - D(r), 2);
  const double md = D(m);
  const double rd = D(rho0);
  const vec4 t = sh::fluid_gradient_term(rij, m, 1.0f / m, rho0, h);
  EXPECT_NEAR(D(t.x), md * g / rd, 1e-5 * md * g / rd);
  EXPECT_NEAR(D(t.w), md * g * g / (rd * rd), 1e-5 * md * g * g / (rd * rd));
  const float c = 0.01f;  // 1% over rest
  const float lambda = sh::fluid_lambda(c, t, 1.0f / m, 0.0f);
  const double expected = -D(c) * rd * rd / (2.0 * md * g * g);
  EXPECT_NEAR(D(lambda), expected, 1e-5 * std::abs(expected));
  // Both particles with the same lambda move apart, by opposite shifts (equal masses).
  const vec3 grad = sh::fluid_spiky_gradient(rij, h);
  const vec3 dxi = sh::fluid_shift_term(lambda, lambda, m, m, 0.0f, grad, rho0);
  const vec3 dxj =
      sh::fluid_shift_term(lambda, lambda, m, m, 0.0f, sh::fluid_spiky_gradient(-rij, h), rho0);
  EXPECT_LT(dxi.x, 0.0f);  // i at the origin moves to -x, away from j
  EXPECT_EQ(dxi.x, -dxj.x);
  // Linearized, each of the two constraints (C_i, C_j: the same pair) changes C_i by -C, so the
  // Jacobi step of both changes it by -2 C.
  const double dc = D(t.x) * (D(dxi.x) - D(dxj.x));  // (m g / rho0) (dx_j - dx_i) along x
  EXPECT_NEAR(dc, -2.0 * D(c), 1e-5);
  // A lone particle: nothing in the denominator but alpha~, and no constraint (below rest).
  EXPECT_EQ(sh::fluid_lambda(0.0f, vec4(0.0f), 1.0f / m, f.density_h.w), 0.0f);
}

TEST(FluidMath, ArtificialPressure) {
  const FluidMaterial f = material(1000.0f, 0.01f);
  const float h = f.density_h.y;
  const float m = f.density_h.z;
  const float dq = f.s_corr.z;
  // -k m h^2 at r = dq, 0 at and beyond h, and (W(r) / W(dq))^4 between.
  EXPECT_NEAR(sh::fluid_s_corr(dq * dq, m, f), -0.1f * m * h * h, 1e-6f * m * h * h);
  EXPECT_EQ(sh::fluid_s_corr(h * h, m, f), 0.0f);
  const float r2 = 0.25f * h * h;
  const double ratio = std::pow((1.0 - 0.25) / (1.0 - 0.04), 3);
  const double mhh = D(m) * D(h) * D(h);
  EXPECT_NEAR(D(sh::fluid_s_corr(r2, m, f)), -0.1 * mhh * std::pow(ratio, 4), 1e-5 * mhh);
}

// A column of fluid at rest under gravity: over a substep h_s the prediction moves each particle
// g h_s^2 down and the constraint's force brings it back, (1 / (rho_0 h_s^2)) sum_j (Lambda_i +
// Lambda_j) m grad W_ij = m g; read as SPH's symmetric pressure force at the rest volume m / rho_0,
// p = -Lambda rho_0 / (m h_s^2). Check the formula's units and sign by hand numbers.
TEST(FluidMath, PressureFromLambda) {
  const float rho0 = 1000.0f;
  const float m = 1e-3f;
  const float hs = 1.0f / 480.0f;
  EXPECT_NEAR(D(sh::fluid_pressure(-2e-9f, rho0, m, hs)), 2e-9 * 1000.0 / (1e-3 * D(hs) * D(hs)),
              1e-4);
  EXPECT_EQ(sh::fluid_pressure(0.0f, rho0, m, hs), 0.0f);
}

// The spiky gradient's first moment: in the continuum, by parts, -int r (x) grad W dV = I (its
// trace, -int r W'(r) 4 pi r^2 dr, is 3 int W dV = 3); on a cubic lattice of spacing d = h / 2,
// (m / rho_0 = d^3) its yy entry is (45 / (16 pi)) (2 (1/4) + 8 (1 - 1/sqrt 2)^2 / sqrt 2 +
// 8 (1 - sqrt 3 / 2)^2 / sqrt 3) = 0.95629 (6 neighbours at d, 2 of them along y; 12 at sqrt 2 d,
// 8 with a y offset; 8 at sqrt 3 d; those at 2 d = h add nothing). The lambdas' pressure of a
// column at rest reads rho g / M_yy (docs/fluids.md, "Pressure").
TEST(FluidMath, GradientMomentOnTheLattice) {
  const float h = 0.02f;
  const float rho0 = 1000.0f;
  const double trace = radial_integral(
      [&](double r) {
        const vec3 t =
            sh::fluid_gradient_moment_term(vec3(static_cast<float>(r), 0.0f, 0.0f), rho0, rho0, h);
        return D(t.x + t.y + t.z);
      },
      D(h));
  EXPECT_NEAR(trace, 3.0, 1e-3);
  const float d = 0.5f * h;
  const float m = rho0 * d * d * d;
  vec3 moment(0.0f);
  for (int x = -2; x <= 2; ++x) {
    for (int y = -2; y <= 2; ++y) {
      for (int z = -2; z <= 2; ++z) {
        const vec3 r(static_cast<float>(x) * d, static_cast<float>(y) * d,
                     static_cast<float>(z) * d);
        moment += sh::fluid_gradient_moment_term(r, m, rho0, h);
      }
    }
  }
  const double s2 = std::sqrt(2.0);
  const double s3 = std::sqrt(3.0);
  const double expected = 45.0 / (16.0 * kPi) *
                          (0.5 + 8.0 * (1.0 - 1.0 / s2) * (1.0 - 1.0 / s2) / s2 +
                           8.0 * (1.0 - s3 / 2.0) * (1.0 - s3 / 2.0) / s3);
  EXPECT_NEAR(expected, 0.95629, 1e-5);
  EXPECT_NEAR(D(moment.x), expected, 1e-5);
  EXPECT_NEAR(D(moment.y), expected, 1e-5);
  EXPECT_NEAR(D(moment.z), expected, 1e-5);
}

TEST(FluidMath, XsphPullsTowardsTheNeighboursVelocity) {
  const float h = 0.02f;
  const vec3 a = sh::fluid_xsph_term(vec3(1.0f, 0.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f), 1e-3f, 1000.0f,
                                     1000.0f, 0.0001f, h);
  EXPECT_EQ(a.x, 0.0f);
  const vec3 b =
      sh::fluid_xsph_term(vec3(0.0f), vec3(2.0f, 0.0f, 0.0f), 1e-3f, 900.0f, 1100.0f, 0.0f, h);
  EXPECT_NEAR(D(b.x), 2.0 * 1e-6 * D(sh::fluid_poly6(0.0f, h)), 1e-6);
}

// The SPH curl of a rigid rotation v = Omega x x over a cubic lattice is about 2 Omega; the
// confinement pushes along N x omega.
TEST(FluidMath, VorticityOfARigidRotation) {
  const float d = 0.01f;
  const float rho0 = 1000.0f;
  const FluidMaterial f = material(rho0, d);
  const float h = f.density_h.y;
  const float m = f.density_h.z;
  const vec3 omega_rigid(0.0f, 0.0f, 3.0f);
  const auto velocity = [&](vec3 x) { return sh::cross(omega_rigid, x); };
  // The lattice's own density (every neighbour sees the same).
  double rho = 0.0;
  for (int x = -2; x <= 2; ++x)
    for (int y = -2; y <= 2; ++y)
      for (int z = -2; z <= 2; ++z) {
        const vec3 r(static_cast<float>(x) * d, static_cast<float>(y) * d,
                     static_cast<float>(z) * d);
        rho += D(m) * D(sh::fluid_poly6(sh::dot(r, r), h));
      }
  const vec3 xi(0.013f, -0.004f, 0.002f);
  vec3 omega;
  for (int x = -2; x <= 2; ++x)
    for (int y = -2; y <= 2; ++y)
      for (int z = -2; z <= 2; ++z) {
        const vec3 off(static_cast<float>(x) * d, static_cast<float>(y) * d,
                       static_cast<float>(z) * d);
        const vec3 xj = xi + off;
        omega += sh::fluid_vorticity_term(velocity(xi), velocity(xj), m, static_cast<float>(rho),
                                          sh::fluid_spiky_gradient(xi - xj, h));
      }
  EXPECT_NEAR(omega.x, 0.0f, 1e-4f);
  EXPECT_NEAR(omega.y, 0.0f, 1e-4f);
  // The spiky gradient over a lattice of h / 2 is not exactly normalized: within 10% of 2 Omega.
  EXPECT_NEAR(omega.z, 6.0f, 0.6f);
  std::printf("[fluid] SPH curl of a rigid rotation 2 Omega = 6: %.4f\n", D(omega.z));
  const vec3 push =
      sh::fluid_confinement(vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 0.0f, 6.0f), 0.5f, 0.01f);
  EXPECT_NEAR(push.y, -0.03f, 1e-7f);  // h_s eps (e_x x 6 e_z) = -6 h_s eps e_y
  const vec3 none = sh::fluid_confinement(vec3(0.0f), omega, 0.5f, 0.01f);
  EXPECT_EQ(none.x, 0.0f);
}

TEST(FluidMath, AkinciSplines) {
  const float h = 0.02f;
  const double h3 = D(h) * D(h) * D(h);
  // Cohesion: continuous at h/2 (both branches h^6 / 64 times 32 / (pi h^9)), 0 at h, negative
  // (repulsive) near 0.
  const float at_half = sh::fluid_cohesion_kernel(0.5f * h, h);
  EXPECT_NEAR(D(at_half), 32.0 / (kPi * h3) / 64.0, 1e-5 * 32.0 / (kPi * h3));
  EXPECT_NEAR(sh::fluid_cohesion_kernel(0.5f * h * 1.0001f, h), at_half, 1e-3f * at_half);
  EXPECT_EQ(sh::fluid_cohesion_kernel(h * 1.001f, h), 0.0f);
  EXPECT_NEAR(sh::fluid_cohesion_kernel(h, h), 0.0f, 1e-6f);
  EXPECT_LT(sh::fluid_cohesion_kernel(0.05f * h, h), 0.0f);
  // Adhesion: 0 up to h/2 and at h; at 3h/4, 0.007 / h^3 (0.25)^(1/4).
  EXPECT_EQ(sh::fluid_adhesion_kernel(0.5f * h, h), 0.0f);
  EXPECT_NEAR(sh::fluid_adhesion_kernel(h, h), 0.0f, 1e-6f);
  EXPECT_NEAR(D(sh::fluid_adhesion_kernel(0.75f * h, h)), 0.007 * std::sqrt(0.5) / h3,
              1e-5 * 0.007 / h3);
  // The adhesion pulls i towards the solid particle b.
  const vec3 v = sh::fluid_adhesion_term(vec3(0.75f * h, 0.0f, 0.0f), 1e-3f, 1.0f, h, 0.01f);
  EXPECT_LT(v.x, 0.0f);
  // Cohesion of two particles with no normals, at 3h/4: pulls i towards j.
  const vec3 c = sh::fluid_cohesion_term(vec3(0.75f * h, 0.0f, 0.0f), 1e-3f, 1000.0f, 1000.0f,
                                         vec3(0.0f), vec3(0.0f), 1000.0f, 1.0f, h, 0.01f);
  EXPECT_LT(c.x, 0.0f);
}

// The solid's side of adhesion (fluid_velocity with MOTES_FLAG_FLUID_ADHESION): the reaction is
// minus the momentum the fluid particle gains from the pair, to the bit; a rigid particle hands
// it to its body (its velocity kept), a free one changes its velocity by R w_b.
TEST(FluidMath, AdhesionReactionKeepsThePairsMomentum) {
  FluidMaterial f = material(1000.0f, 0.01f);
  f.velocity.w = 2.0f;  // beta
  const float h = f.density_h.y, mi = f.density_h.z, hs = 1.0f / 960.0f;
  const vec3 xi(0.0f, 0.0f, 0.0f);
  const vec3 xb(0.7f * h, 0.1f * h, -0.05f * h);
  const float rb = 0.005f;
  const vec3 term =
      sh::fluid_adhesion_term(xi - xb, sh::fluid_neighbour_mass(false, 0.0f, rb, f), 2.0f, h, hs);
  ASSERT_GT(sh::length(term), 0.0f);
  const vec3 r = sh::fluid_adhesion_reaction(xi, xb, rb, f, hs);
  EXPECT_EQ(r.x, -(term.x * mi));
  EXPECT_EQ(r.y, -(term.y * mi));
  EXPECT_EQ(r.z, -(term.z * mi));
  EXPECT_GT(term.x, 0.0f) << "the fluid particle is pulled towards the solid (+x)";
  EXPECT_LT(r.x, 0.0f) << "the solid is pulled towards the fluid particle (-x)";
  const vec4 vb(0.1f, 0.2f, 0.3f, 4.0f);
  const vec4 rigid = sh::fluid_adhesion_taken(vb, r, true);
  EXPECT_EQ(rigid.x, vb.x);
  EXPECT_EQ(rigid.w, vb.w);
  const vec4 free = sh::fluid_adhesion_taken(vb, r, false);
  EXPECT_EQ(free.x, vb.x + r.x * 4.0f);
  EXPECT_EQ(free.w, 4.0f);
}

}  // namespace
