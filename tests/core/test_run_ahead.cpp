// Velocity Verlet running ahead (core/step/integrators.hpp closing_kick_drift): when nothing looks
// at the state between two steps, the closing half kick of the first and the kick-drift of the
// second are one pass over the store. That pass must leave every field, every mirror line and
// every sum of the round bit for bit as the two passes do, and a run that runs ahead must end
// bit for bit as the run that never does, energy ledger included. A step that fails after
// running ahead reports the failure of the step that failed.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <utility>

#include "core/fast/kinematics_mirror.hpp"
#include "core/run/simulation.hpp"
#include "core/step/integrators.hpp"
#include "support/compare.hpp"
#include "support/random_store.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::fill_random_store;
using testing_support::same_bits;

using testing_support::expect_same_particles;
using testing_support::thesis_drum_scene;

// A store whose forces, elastic forces and velocities are all nonzero and unrelated, so that
// every term of the closing kick and its sums is seen.

void expect_same_closing(const ClosingKick& a, const ClosingKick& b) {
  EXPECT_TRUE(same_bits(a.checksum, b.checksum)) << a.checksum << " " << b.checksum;
  EXPECT_TRUE(same_bits(a.disp2, b.disp2));
  EXPECT_TRUE(same_bits(a.speed2, b.speed2));
  EXPECT_TRUE(same_bits(a.motion2, b.motion2));
  EXPECT_TRUE(same_bits(a.late_loss, b.late_loss)) << a.late_loss << " " << b.late_loss;
}

// Two passes (closing_kick, then kick_drift_owned) against the fused one, four at a time or
// not, for counts with and without whole eights and fours.
void expect_same_pass(std::size_t n, bool four_at_a_time, bool mirror) {
  const auto seed = 11u + static_cast<std::uint32_t>(n);
  ParticleStore two, one;
  fill_random_store(two, n, seed);
  fill_random_store(one, n, seed);
  std::vector<Vec2> x_build(n);
  std::mt19937_64 rng(seed + 1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Vec2& xb : x_build) xb = {u(rng), u(rng)};
  Array<PairKinematics> lines_two(n), lines_one(n);
  const double dt = 0.37;  // large: the products round visibly into the sums
  const Vec2 g{0.3, -9.81};
  const ClosingKick c_two = closing_kick(two, x_build.data(), dt, g, !four_at_a_time);
  kick_drift_owned(two, dt, mirror ? lines_two.data() : nullptr, four_at_a_time);
  const ClosingKick c_one = closing_kick_drift(one, x_build.data(), dt, g,
                                               mirror ? lines_one.data() : nullptr, four_at_a_time);
  SCOPED_TRACE(testing::Message() << "n " << n << ", four at a time " << four_at_a_time);
  expect_same_closing(c_one, c_two);
  for (std::size_t k = 0; k < n; ++k) {
    SCOPED_TRACE(testing::Message() << "particle " << k);
    EXPECT_TRUE(same_bits(one.pos[k], two.pos[k]));
    EXPECT_TRUE(same_bits(one.vel[k], two.vel[k]));
    EXPECT_TRUE(same_bits(one.omega[k], two.omega[k]));
    EXPECT_TRUE(same_bits(one.theta[k], two.theta[k]));
    EXPECT_TRUE(same_bits(one.acc[k], two.acc[k]));
    EXPECT_TRUE(same_bits(one.alpha[k], two.alpha[k]));
    EXPECT_TRUE(same_bits(one.force[k], Vec2{}));
    EXPECT_TRUE(same_bits(one.torque[k], 0.0));
    EXPECT_TRUE(same_bits(one.elastic_force[k], Vec2{}));
    if (mirror) {
      EXPECT_TRUE(same_bits(lines_one[k], lines_two[k]));
    }
  }
}

TEST(VelocityVerletRunAhead, OnePassChangesNoBit) {
  for (std::size_t n : {1u, 3u, 4u, 7u, 8u, 12u, 13u, 16u, 67u, 1000u}) {
    expect_same_pass(n, false, false);
    expect_same_pass(n, true, false);
  }
}

TEST(VelocityVerletRunAhead, OnePassWritesTheSameMirrorLines) {
  if (!DEM2D_VECTOR_GATHER) GTEST_SKIP() << "no AVX-512 here: no mirror";
  for (std::size_t n : {1u, 4u, 8u, 13u, 67u}) {
    expect_same_pass(n, true, true);
    expect_same_pass(n, false, true);
  }
}

// The sums' order is the one documented (ClosingKick): lanes k mod 8 over the whole eights,
// lane 0 for the rest, the lanes added in turn. Recomputed here from the terms.
TEST(VelocityVerletRunAhead, SumsTakeTheDocumentedOrder) {
  for (std::size_t n : {5u, 8u, 29u, 1000u}) {
    for (const bool four : {false, true}) {
      ParticleStore p, q;
      fill_random_store(p, n, 3u);
      fill_random_store(q, n, 3u);
      std::vector<Vec2> x_build(n, Vec2{0.1, -0.2});
      const double dt = 0.37, h = 0.5 * dt;
      const Vec2 g{0.0, -9.81};
      const ClosingKick c = closing_kick(p, x_build.data(), dt, g, four);
      double late_lanes[8] = {}, check_lanes[8] = {};
      const std::size_t whole = n / 8 * 8;
      for (std::size_t k = 0; k < n; ++k) {
        const Vec2 a = q.inv_mass[k] * q.force[k] + g;
        const double al = q.inv_inertia[k] * q.torque[k];
        const std::size_t lane = k < whole ? k % 8 : 0;
        late_lanes[lane] += dot(q.force[k] - q.elastic_force[k], h * a) + q.torque[k] * (h * al);
        check_lanes[lane] += (a.x + a.y) + al + (q.pos[k].x + q.pos[k].y);
      }
      double late = 0.0, checksum = 0.0;
      for (std::size_t l = 0; l < 8; ++l) {
        late += late_lanes[l];
        checksum += check_lanes[l];
      }
      EXPECT_TRUE(same_bits(c.late_loss, -dt * late)) << "n " << n << ", four " << four;
      EXPECT_TRUE(same_bits(c.checksum, checksum)) << "n " << n << ", four " << four;
    }
  }
}

// A drum run stepped with run_until runs ahead at most steps; it must end as the run that
// never does: every field of every particle, the energy ledger, the contacts, the rebuilds.
// Both runs to time t: every field of every particle and the energy ledger, bit for bit.
void run_both_and_compare(Simulation& whole, Simulation& ahead, double t) {
  whole.run_until(t);
  ahead.run_until(t);
  expect_same_particles(whole, ahead);
  testing_support::expect_same_ledger(whole, ahead);
}

TEST(VelocityVerletRunAhead, ARunThatRunsAheadEndsBitForBitAsOneThatDoesNot) {
  Scene scene = thesis_drum_scene(120, 1.8, 16, 0.1);
  Simulation whole(scene), ahead(scene);
  whole.set_run_ahead(false);
  for (const double t : {0.05, 0.1234, 0.25}) {
    SCOPED_TRACE(testing::Message() << "t = " << t);
    run_both_and_compare(whole, ahead, t);
    EXPECT_EQ(ahead.last_totals().contacts, whole.last_totals().contacts);
    EXPECT_EQ(ahead.neighbor_builds(), whole.neighbor_builds());
  }
  EXPECT_EQ(whole.steps_run_ahead(), 0);
  EXPECT_GT(ahead.steps_run_ahead(), ahead.step_count() / 2) << "most steps should run ahead";
  EXPECT_LT(ahead.steps_run_ahead(), ahead.step_count());
  EXPECT_GT(whole.neighbor_builds(), 3) << "the run should rebuild between run-ahead steps";
  EXPECT_GT(whole.diagnostics().dissipated_energy, 0.0);
}

// Ore breaks, is fed and leaves through the sieve: the ore models plan each step's population
// step from its force evaluation, and the step runs ahead when the plan changes nothing. The
// run must end as the run that never runs ahead: every field of every particle (damage
// included), the energy ledger, the grinding's counts and masses.
TEST(VelocityVerletRunAhead, AGrindingRunThatRunsAheadEndsBitForBitAsOneThatDoesNot) {
  const Scene scene = testing_support::grinding_drum_scene();
  Simulation whole(scene), ahead(scene);
  whole.set_run_ahead(false);
  for (const double t : {0.15, 0.4}) {
    SCOPED_TRACE(testing::Message() << "t = " << t);
    run_both_and_compare(whole, ahead, t);
    const GrindingTotals& ga = ahead.grinding()->totals();
    const GrindingTotals& gb = whole.grinding()->totals();
    EXPECT_EQ(ga.breakages, gb.breakages);
    EXPECT_EQ(ga.fragments, gb.fragments);
    EXPECT_EQ(ga.fed_count, gb.fed_count);
    EXPECT_EQ(ga.discharged_count, gb.discharged_count);
    EXPECT_TRUE(same_bits(ga.discharged_mass, gb.discharged_mass));
  }
  const GrindingTotals& g = ahead.grinding()->totals();
  EXPECT_GT(g.breakages, 0);
  EXPECT_GT(g.fed_count, 0);
  EXPECT_GT(g.discharged_count, 0);
  EXPECT_EQ(whole.steps_run_ahead(), 0);
  EXPECT_GT(ahead.steps_run_ahead(), ahead.step_count() / 2) << "most steps should run ahead";
}

// The store really is one drift ahead between two steps that run ahead, and whole after a step
// whose end is observed.
TEST(VelocityVerletRunAhead, OnlyStepsWhoseEndNobodyReadsRunAhead) {
  Scene scene = thesis_drum_scene(60, 1.8, 16, 0.1);
  Simulation ahead(scene), whole(scene);
  whole.set_run_ahead(false);
  whole.run_until(0.01);
  ahead.run_until(0.01);
  // Ahead: positions already moved by the next drift, so they differ from the whole state (a
  // step that rebuilds or is backed up does not run ahead: several steps).
  int ran_ahead = 0;
  for (int k = 0; k < 5; ++k) {
    ahead.step(/*end_observed=*/false);
    whole.step();
    int moved = 0;
    for (std::size_t q = 0; q < ahead.particles().n_owned(); ++q)
      moved += !same_bits(ahead.particles().pos[q], whole.particles().pos[q]);
    ran_ahead += moved > 0;
  }
  EXPECT_GE(ran_ahead, 3);
  ahead.step();  // observed: ends whole
  whole.step();
  expect_same_particles(whole, ahead);
}

// A step that fails after running ahead: the same message and step as the run that never runs
// ahead, and the store stepped back to that step's end state, to the last bits (x - dt v, ...).
// A ball is given 1.2 radii per step between two observed steps: the next step (its rebuild was
// decided before) runs ahead and its round finds the motion.
TEST(VelocityVerletRunAhead, AFailedStepReportsAsTheRunThatDoesNotRunAhead) {
  const Scene s = thesis_drum_scene(120, 1.8, 16, 0.1);
  Simulation whole(s), ahead(s);
  whole.set_run_ahead(false);
  whole.run_until(0.02);
  ahead.run_until(0.02);
  expect_same_particles(whole, ahead);
  const std::int64_t ran_before = ahead.steps_run_ahead();
  const auto fail = [](Simulation& sim, bool end_observed) {
    ParticleStore& p = sim.particles();
    p.vel[7] = {1.2 * p.radius[7] / sim.dt(), 0.0};
    try {
      for (int k = 0; k < 3; ++k) sim.step(end_observed);
    } catch (const UnstableError& e) {
      return std::pair<std::string, std::int64_t>{e.what(), e.step()};
    }
    return std::pair<std::string, std::int64_t>{"", -1};
  };
  const auto [what_whole, step_whole] = fail(whole, true);
  const auto [what_ahead, step_ahead] = fail(ahead, false);
  ASSERT_GT(step_whole, 0) << "1.2 radii per step should be refused";
  EXPECT_NE(what_whole.find("moves"), std::string::npos) << what_whole;
  EXPECT_EQ(step_ahead, step_whole);
  EXPECT_EQ(what_ahead, what_whole);
  EXPECT_EQ(ahead.steps_run_ahead(), ran_before + 1) << "the failed step should have run ahead";
  const ParticleStore& p = whole.particles();
  const ParticleStore& q = ahead.particles();
  ASSERT_EQ(p.n_owned(), q.n_owned());
  int differ = 0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    SCOPED_TRACE(testing::Message() << "particle " << k);
    const double v_scale = 1.0 + norm(p.vel[k]);
    EXPECT_LT(norm(q.pos[k] - p.pos[k]), 1e-14 * (1.0 + norm(p.pos[k]) + v_scale * s.run.dt));
    EXPECT_LT(norm(q.vel[k] - p.vel[k]), 1e-13 * v_scale);
    EXPECT_LT(std::abs(q.omega[k] - p.omega[k]), 1e-13 * (1.0 + std::abs(p.omega[k])));
    EXPECT_LT(std::abs(q.theta[k] - p.theta[k]), 1e-13 * (1.0 + std::abs(p.theta[k])));
    differ += !same_bits(q.pos[k], p.pos[k]) || !same_bits(q.vel[k], p.vel[k]);
  }
  std::cout << "[ failure ] " << what_ahead << "\n  particles whose state differs in the last "
            << "bits after the step back: " << differ << " of " << p.n_owned() << "\n";
}

}  // namespace
}  // namespace dem2d
