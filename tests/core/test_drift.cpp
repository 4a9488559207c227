// Velocity Verlet's drift (core/step/integrators.hpp kick_drift_owned): with AVX-512 it moves four
// particles per iteration. It must leave every field it writes, and the pair gather's mirror
// lines, the same bit for bit as the one-at-a-time loop, for any count (whole fours and a tail).
#include <gtest/gtest.h>

#include "core/fast/kinematics_mirror.hpp"
#include "core/step/integrators.hpp"
#include "support/random_store.hpp"

namespace dem2d {
namespace {

using testing_support::fill_random_store;
using testing_support::same_bits;

void expect_same_drift(std::size_t n, bool mirror) {
  const auto seed = 7u + static_cast<std::uint32_t>(n);
  ParticleStore one, four, start;
  fill_random_store(one, n, seed);
  fill_random_store(four, n, seed);
  fill_random_store(start, n, seed);
  Array<PairKinematics> lines_one(n), lines_four(n);
  const double dt = 0.37;  // large: the products round visibly into the sums
  kick_drift_owned(one, dt, mirror ? lines_one.data() : nullptr, false);
  kick_drift_owned(four, dt, mirror ? lines_four.data() : nullptr, true);
  for (std::size_t k = 0; k < n; ++k) {
    SCOPED_TRACE(testing::Message() << "n " << n << ", particle " << k);
    EXPECT_TRUE(same_bits(four.pos[k], one.pos[k]));
    EXPECT_TRUE(same_bits(four.vel[k], one.vel[k]));
    EXPECT_TRUE(same_bits(four.omega[k], one.omega[k]));
    EXPECT_TRUE(same_bits(four.theta[k], one.theta[k]));
    EXPECT_TRUE(same_bits(four.force[k], Vec2{}));
    EXPECT_TRUE(same_bits(four.torque[k], 0.0));
    if (mirror) {
      EXPECT_TRUE(same_bits(lines_four[k], lines_one[k]));
    }
  }
  // The drift moved every particle (the comparison is not of untouched stores).
  for (std::size_t k = 0; k < n; ++k) EXPECT_FALSE(same_bits(four.pos[k], start.pos[k]));
}

TEST(VelocityVerletDrift, FourAtATimeChangesNoBit) {
  for (std::size_t n : {1u, 3u, 4u, 5u, 8u, 11u, 64u, 67u}) expect_same_drift(n, false);
}

TEST(VelocityVerletDrift, FourAtATimeWritesTheSameMirrorLines) {
  if (!DEM2D_VECTOR_GATHER) GTEST_SKIP() << "no AVX-512 here: no mirror and one loop only";
  for (std::size_t n : {1u, 3u, 4u, 5u, 8u, 11u, 64u, 67u}) expect_same_drift(n, true);
}

}  // namespace
}  // namespace dem2d
