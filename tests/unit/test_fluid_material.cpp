// The host side of fluid materials (motes/fluid.h): the FluidMaterials defaults from the parameter
// set settled with the prototype (docs/fluids.md, "Settled with the prototype").
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "motes/fluid.h"

namespace {

motes::Material water() {
  motes::Material m;
  m.name = "water";
  m.density = 1000.0;
  return m;
}

// D_rest = 0.3734 m / (rho_0^2 d^8) (docs/fluids.md, "The method"), at any d and rho_0.
TEST(FluidMaterial, RestDenominatorIsTheLatticeSum) {
  for (const double d : {0.01, 0.05, 0.002}) {
    for (const double rho0 : {1000.0, 500.0}) {
      const double m = rho0 * d * d * d;
      const double k = motes::fluid_rest_denominator(rho0, d) * rho0 * rho0 * std::pow(d, 8) / m;
      EXPECT_NEAR(k, 0.3734, 5e-4) << "d " << d << " rho_0 " << rho0;
    }
  }
}

TEST(FluidMaterial, DefaultsAreTheSettledSet) {
  const double d = 0.01;
  const motes::shared::FluidMaterial f = motes::fluid_material(water(), d, 1.0 / 960.0);
  EXPECT_FLOAT_EQ(f.density_h.x, 1000.0f);
  EXPECT_FLOAT_EQ(f.density_h.y, 0.02f);  // h = 2 d
  EXPECT_FLOAT_EQ(f.density_h.z, 1e-3f);  // m = rho_0 d^3
  EXPECT_FLOAT_EQ(f.density_h.w,
                  static_cast<float>(0.5 * motes::fluid_rest_denominator(1000.0, d)));
  EXPECT_FLOAT_EQ(f.s_corr.x, 0.015f);   // k at 16 substeps of 1/60 s
  EXPECT_EQ(f.s_corr.y, 4.0f);           // n
  EXPECT_FLOAT_EQ(f.s_corr.z, 0.004f);   // dq = 0.2 h
  EXPECT_EQ(f.s_corr.w, 1.0f);           // solid scale s
  EXPECT_FLOAT_EQ(f.velocity.x, 0.01f);  // XSPH c
  EXPECT_EQ(f.velocity.y, 0.0f);
  EXPECT_EQ(f.velocity.z, 0.0f);
  EXPECT_EQ(f.velocity.w, 0.0f);
  // h is 4 r exactly, as the neighbour rule forms it from the particle's radius.
  EXPECT_EQ(f.density_h.y, 4.0f * static_cast<float>(d / 2.0));
}

// The fill's spacing: the poly6 sum of its lattice is rho_0 (1.0098 rho_0 at spacing d).
TEST(FluidMaterial, RestSpacingHoldsTheRestDensity) {
  const double d = 0.01;
  const double s = motes::fluid_rest_spacing(d);
  EXPECT_NEAR(s / d, 1.003075, 1e-6);
  const motes::shared::FluidMaterial f = motes::fluid_material(water(), d, 1.0 / 960.0);
  double rho = 0.0;
  for (int x = -2; x <= 2; ++x) {
    for (int y = -2; y <= 2; ++y) {
      for (int z = -2; z <= 2; ++z) {
        const double r2 = s * s * (x * x + y * y + z * z);
        rho += static_cast<double>(f.density_h.z) * static_cast<double>(motes::shared::fluid_poly6(
                                                        static_cast<float>(r2), f.density_h.y));
      }
    }
  }
  EXPECT_NEAR(rho / 1000.0, 1.0, 2e-6);
}

// s_corr is the force of a pair potential: -du/dr of fluid_s_corr_energy is m dx / h_s^2 times
// the sweeps, dx the shift term s_corr gives i (fluid_shift_term), at several distances; 0 from h.
TEST(FluidMaterial, ArtificialPressureIsThePairPotentialsForce) {
  const double d = 0.01, hs = 1.0 / 960.0;
  const int sweeps = 2;
  const motes::shared::FluidMaterial f = motes::fluid_material(water(), d, hs);
  const float h = f.density_h.y, m = f.density_h.z;
  for (const double q : {0.25, 0.45, 0.6, 0.8}) {
    const double r = q * static_cast<double>(h), e = 1e-5 * static_cast<double>(h);
    const double force = -(motes::fluid_s_corr_energy(r + e, f, hs, sweeps) -
                           motes::fluid_s_corr_energy(r - e, f, hs, sweeps)) /
                         (2.0 * e);
    const motes::shared::vec3 rij(static_cast<float>(r), 0.0f, 0.0f);
    const float s_corr = motes::shared::fluid_s_corr(static_cast<float>(r * r), m, f);
    const motes::shared::vec3 dx = motes::shared::fluid_shift_term(
        0.0f, 0.0f, m, m, s_corr, motes::shared::fluid_spiky_gradient(rij, h), f.density_h.x);
    const double moved = static_cast<double>(dx.x) * sweeps * static_cast<double>(m) / (hs * hs);
    EXPECT_GT(force, 0.0) << "a repulsion, q " << q;
    EXPECT_NEAR(moved / force, 1.0, 1e-4) << "q " << q;
  }
  EXPECT_EQ(motes::fluid_s_corr_energy(static_cast<double>(h), f, hs, sweeps), 0.0);
}

TEST(FluidMaterial, RestDensityOverridesDensityAndKFollowsTheSubstep) {
  motes::Material m = water();
  m.rest_density = 998.0;
  const motes::shared::FluidMaterial f = motes::fluid_material(m, 0.01, 1.0 / 480.0);
  EXPECT_FLOAT_EQ(f.density_h.x, 998.0f);
  EXPECT_FLOAT_EQ(f.s_corr.x, 0.03f);  // 8 substeps of 1/60 s
}

TEST(FluidMaterial, TableHasAnEntryPerMaterialAndRefusesTwoSizesOfOne) {
  motes::Scene scene;
  scene.source = "tank.json";
  scene.materials = {water(), water()};
  scene.materials[0].name = "steel";
  scene.materials[1].name = "water";
  motes::FluidSpec a;
  a.name = "a";
  a.material = 1;
  a.diameter = 0.01;
  scene.fluids = {a};
  const auto table = motes::fluid_materials(scene, 1.0 / 960.0);
  ASSERT_TRUE(table.is_ok()) << table.message();
  ASSERT_EQ(table->size(), 2u);
  EXPECT_EQ(table.value()[0].density_h.x, 0.0f);
  EXPECT_FLOAT_EQ(table.value()[1].density_h.y, 0.02f);
  motes::FluidSpec b = a;
  b.name = "b";
  b.diameter = 0.02;
  scene.fluids.push_back(b);
  const auto refused = motes::fluid_materials(scene, 1.0 / 960.0);
  ASSERT_FALSE(refused.is_ok());
  EXPECT_NE(refused.message().find("fluid \"b\": material \"water\""), std::string::npos)
      << refused.message();
}

}  // namespace
