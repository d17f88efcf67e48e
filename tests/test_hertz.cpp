// Hertz stiffness: both modulus conventions, effective radius (Eq. 27-29).
#include <cmath>

#include <gtest/gtest.h>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/error.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::collision;
using impactdeck::test::kClosedFormRel;

TEST(Hertz, ModulusConventions) {
  const ElasticMaterial steel{2.05e11, 0.3}, alu{7.0e10, 0.33};
  const double hertz = effective_modulus_Pa(steel, alu, ModulusConvention::hertz);
  const double paper = effective_modulus_Pa(steel, alu, ModulusConvention::paper);
  EXPECT_NEAR(hertz, 1.0 / ((1 - 0.09) / 2.05e11 + (1 - 0.1089) / 7.0e10), kClosedFormRel * hertz);
  EXPECT_NEAR(paper, 1.0 / (1 / 2.05e11 + 1 / 7.0e10), kClosedFormRel * paper);
  // Same material, paper convention: E/2.
  EXPECT_DOUBLE_EQ(effective_modulus_Pa(steel, steel, ModulusConvention::paper), 1.025e11);
  EXPECT_GT(hertz, paper);  // the Poisson term stiffens
}

TEST(Hertz, EffectiveRadiusAndPlane) {
  EXPECT_DOUBLE_EQ(effective_radius_m(1 / 0.5, 1 / 0.05), 0.5 * 0.05 / 0.55);
  EXPECT_DOUBLE_EQ(effective_radius_m(0.0, 1 / 0.05), 0.05);  // sphere on a plane
  EXPECT_THROW(effective_radius_m(0.0, 0.0), InputError);
  EXPECT_THROW(effective_radius_m(-1.0, 2.0), InputError);
}

TEST(Hertz, Constant) {
  EXPECT_DOUBLE_EQ(hertz_constant(1e11, 0.04), 4.0 / 3.0 * 1e11 * 0.2);
}

TEST(Hertz, RejectsBadMaterials) {
  const ElasticMaterial ok{2e11, 0.3};
  try {
    effective_modulus_Pa({-1.0, 0.3}, ok, ModulusConvention::hertz);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("youngs_modulus_Pa"), std::string::npos) << e.what();
  }
  EXPECT_THROW(effective_modulus_Pa({2e11, 0.5}, ok, ModulusConvention::hertz), InputError);
  EXPECT_THROW(effective_modulus_Pa(ok, {2e11, -1.0}, ModulusConvention::hertz), InputError);
}
