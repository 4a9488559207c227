// Restitution map of the clamped Hertz and linear laws (docs/validation.md, "Restitution with a
// clamped normal force").
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/contact/materials.hpp"

namespace dem2d {
namespace {

double unclamped_beta(double e) {
  const double l = std::log(e);
  return l / std::sqrt(l * l + std::numbers::pi * std::numbers::pi);
}

// docs/validation.md, "Restitution with a clamped normal force": restitution obtained with the
// unclamped damping law once the force is clamped at zero (Antypov & Elliott 2011; Thornton,
// Cummins & Cleary 2013).
TEST(Restitution, ClampedHertzWithUnclampedBetaMatchesPublishedTable) {
  const double asked[] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.98};
  const double obtained[] = {0.2527, 0.3249, 0.3971, 0.4720, 0.5503,
                             0.6323, 0.7182, 0.8081, 0.9020, 0.9801};
  for (int k = 0; k < 10; ++k)
    EXPECT_NEAR(restitution_hertz_clamped(unclamped_beta(asked[k])), obtained[k], 6e-5)
        << "e = " << asked[k];
}

TEST(Restitution, MappedBetaGivesBackTheAskedRestitution) {
  for (double e = 0.1; e <= 1.0001; e += 0.05) {
    EXPECT_NEAR(restitution_hertz_clamped(hertz_beta_for_restitution(e)), e, 1e-6);
    EXPECT_NEAR(restitution_linear_clamped(linear_gamma_for_restitution(e)), e, 1e-6);
  }
  EXPECT_EQ(hertz_beta_for_restitution(1.0), 0.0);
}

}  // namespace
}  // namespace dem2d
