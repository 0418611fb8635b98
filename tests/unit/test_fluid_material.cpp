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
