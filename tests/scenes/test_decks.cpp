// The shipped decks do what their header comments say: each is loaded through the deck parser
// and run (shortened where noted) with the physics checked against closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <string>

#include "core/run/simulation.hpp"
#include "io/deck.hpp"

namespace dem2d {
namespace {

Scene deck(const std::string& name, const std::vector<std::string>& sets = {}) {
  return load_deck(std::string(DEM2D_SOURCE_DIR) + "/inputs/" + name, sets);
}

// impact.in: two steel balls at 2 x 5 m/s. With e = 1 the contact lasts
// t_c = 2.868 (m*^2/(R* E*^2 v))^(1/5) and the peak overlap is (15 m* v^2/(16 E* sqrt(R*)))^(2/5)
// (Johnson 1985); with the deck's e = 0.73 they part at 0.73 of the approach speed.
TEST(Decks, ImpactHertzContactTimeOverlapAndRestitution) {
  for (double e : {1.0, 0.73}) {
    Scene s = deck("impact.in", {"material.steel.restitution=" + std::to_string(e)});
    Simulation sim(s);
    const double m = sim.particles().mass[0];
    const double m_eff = 0.5 * m, r_eff = 0.05, v = 10.0;
    const double e_star = 2e11 / (2.0 * (1.0 - 0.0625));
    double first = -1, last = -1, peak = 0;
    while (sim.time() < s.run.duration) {
      sim.step();
      const double overlap = 0.2 - norm(sim.particles().pos[1] - sim.particles().pos[0]);
      if (overlap > 0) {
        if (first < 0) first = sim.time();
        last = sim.time();
        peak = std::max(peak, overlap);
      }
    }
    const double v_after = sim.particles().vel[1].x - sim.particles().vel[0].x;
    // At the deck's automatic dt (about 18 steps per contact) Verlet keeps it within 1 %.
    EXPECT_NEAR(v_after / v, e, 1e-2 * e) << "e = " << e;
    if (e == 1.0) {
      const double tc = 2.868 * std::pow(m_eff * m_eff / (r_eff * e_star * e_star * v), 0.2);
      const double dmax = std::pow(15 * m_eff * v * v / (16 * e_star * std::sqrt(r_eff)), 0.4);
      EXPECT_NEAR(last - first, tc, 2.0 * sim.dt() + 2e-3 * tc);
      EXPECT_NEAR(peak, dmax, 2e-3 * dmax);
      EXPECT_NEAR(tc, 3.91e-4, 1e-6);  // the number in the deck's header
      EXPECT_NEAR(dmax, 1.33e-3, 5e-6);
    }
  }
}

// drop.in: each bounce returns the ball to e^2 of the height it fell from.
TEST(Decks, DropReboundHeightsFollowRestitutionSquared) {
  Scene s = deck("drop.in");
  Simulation sim(s);
  const double r = 0.05, e = 0.73;
  double prev_vy = 0.0, apex = 0.0;
  std::vector<double> apexes;
  const double h0 = sim.particles().pos[0].y - r;
  while (sim.time() < 1.6) {
    sim.step();
    const double vy = sim.particles().vel[0].y;
    const double y = sim.particles().pos[0].y - r;
    if (prev_vy > 0 && vy <= 0) apexes.push_back(y);
    apex = std::max(apex, y);
    prev_vy = vy;
  }
  ASSERT_GE(apexes.size(), 2u);
  EXPECT_NEAR(apexes[0] / h0, e * e, 0.01 * e * e);  // 0.533 m
  EXPECT_NEAR(apexes[1] / apexes[0], e * e, 0.01 * e * e);
}

// incline.in: rolls without slip down 10 degrees at a = 5/7 g (sin t - mu_r cos t) = 0.8717 m/s^2.
TEST(Decks, InclineRollsAtFiveSeventhsWithRollingFriction) {
  Scene s = deck("incline.in");
  Simulation sim(s);
  const double t = 10.0 * std::numbers::pi / 180.0;
  const Vec2 down{-std::cos(t), -std::sin(t)};
  sim.run_until(0.2);
  const double v0 = dot(sim.particles().vel[0], down);
  const double t0 = sim.time();
  sim.run_until(1.2);
  const double a = (dot(sim.particles().vel[0], down) - v0) / (sim.time() - t0);
  EXPECT_NEAR(a, 5.0 / 7.0 * 9.81 * (std::sin(t) - 0.05 * std::cos(t)), 0.01 * 0.8717);
  EXPECT_NEAR(a, 0.8717, 0.01);
  // No slip: the contact point is at rest, v = -w r.
  EXPECT_NEAR(dot(sim.particles().vel[0], down), sim.particles().omega[0] * 0.05, 1e-3);
}

// The thesis decks: --check numbers of the waterfall deck (fill fraction 240 pi 0.1^2 / pi 2.5^2).
TEST(Decks, ThesisDecksResolveTableOneValues) {
  for (const char* name : {"cascade.in", "cascade_cataract.in", "waterfall.in", "centrifuge.in",
                           "waterfall_polygon.in"}) {
    const Scene s = deck(name);
    ASSERT_GE(s.materials.size(), 1u) << name;
    EXPECT_EQ(s.materials[0].name, "steel");
    EXPECT_EQ(s.fills[0].material, "steel");
    EXPECT_DOUBLE_EQ(s.materials[0].youngs_modulus, 2e11);
    EXPECT_DOUBLE_EQ(s.materials[0].shear_modulus, 8e10);
    EXPECT_DOUBLE_EQ(s.materials[0].density, 7800);
    EXPECT_DOUBLE_EQ(s.materials[0].sliding_friction, 0.1);
    EXPECT_DOUBLE_EQ(s.materials[0].rolling_friction, 0.05);
    EXPECT_DOUBLE_EQ(s.run.dt, 1e-5);
    EXPECT_DOUBLE_EQ(s.run.duration, 10.0);
    EXPECT_DOUBLE_EQ(s.drum.radius, 2.5);
    EXPECT_EQ(s.fills[0].radius_min, 0.1);
  }
  const Scene w = deck("waterfall.in");
  EXPECT_EQ(w.fills[0].count, 240);
  EXPECT_DOUBLE_EQ(w.drum.speed, 1.8);
  // The liners that give each deck its regime (the deck headers, docs/validation.md).
  EXPECT_EQ(w.drum.lifters.at(0).count, 24);
  EXPECT_EQ(deck("cascade.in").drum.lifters.at(0).count, 16);
  const Scene mixed = deck("cascade_cataract.in");
  EXPECT_EQ(mixed.drum.material, "liner");
  EXPECT_DOUBLE_EQ(mixed.materials.at(1).sliding_friction, 0.4);
  EXPECT_EQ(deck("waterfall_polygon.in").drum.sides, 16);
}

// The regime classifier (core/mill/mill_analytics.hpp) on the shipped regime decks, run whole (10
// s, a series row every 1 ms as the decks write them): over the last 5 s the regime of most rows is
// the one the deck's name says, and so is the run's (the last window's).
TEST(Decks, RegimeDecksAreClassifiedAsTheirNamesSay) {
  const std::pair<const char*, Regime> cases[] = {{"cascade.in", Regime::kCascading},
                                                  {"cascade_cataract.in", Regime::kMixed},
                                                  {"waterfall.in", Regime::kCataracting},
                                                  {"centrifuge.in", Regime::kCentrifuging}};
  for (const auto& [name, expected] : cases) {
    Simulation sim(deck(name));
    std::map<std::string, int> rows;
    while (sim.time() + 0.5 * sim.dt() < sim.scene().run.duration) {
      sim.run_until(sim.time() + sim.scene().output.series_interval);
      const SeriesRow row = sim.record_row();
      if (row.time > 5.0) ++rows[row.regime];
    }
    const auto most = std::max_element(
        rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    int total = 0;
    for (const auto& [regime, count] : rows) total += count;
    std::cout << "[ regime ] " << name << ": " << most->first << " in " << most->second << " of "
              << total << " rows over 5-10 s; the run: " << regime_name(sim.mill_summary().regime)
              << "\n";
    EXPECT_EQ(most->first, regime_name(expected)) << name;
    EXPECT_GT(most->second, total / 2) << name;
    EXPECT_EQ(sim.mill_summary().regime, expected) << name;
  }
}

// lifters.in: the lifters carry the charge up; the same smooth shell without them lets it slip.
TEST(Decks, LiftersLiftTheChargeThatASmoothShellLetsSlip) {
  auto charge_angle = [](Scene s) {
    Simulation sim(s);
    sim.run_until(1.5);
    double angle = 0.0;
    int samples = 0;
    while (sim.time() < 4.5) {  // a whole rocking period of the slipping block (docs/models.md)
      sim.run_until(sim.time() + 0.05);
      Vec2 cm{};
      const auto& p = sim.particles();
      for (std::size_t k = 0; k < p.n_owned(); ++k) cm += p.pos[k];
      angle += std::atan2(cm.x, -cm.y) * 180.0 / std::numbers::pi;
      ++samples;
    }
    return angle / samples;
  };
  Scene with = deck("lifters.in");
  Scene without = with;
  without.drum.lifters.clear();
  const double a_with = charge_angle(with), a_without = charge_angle(without);
  std::cout << "charge centre of mass angle: with lifters " << a_with << " deg, without "
            << a_without << " deg\n";
  // Measured: about 50 deg with lifters, 16 deg without (the block slips and rocks).
  EXPECT_GT(a_with, 40.0);
  EXPECT_LT(a_without, 20.0);
}

}  // namespace
}  // namespace dem2d
