// Superellipses in whole runs (core/run/simulation.hpp) against closed forms:
//   - restitution of centred head-on impacts (ellipses tip to tip and side to side, rounded
//     squares face to face): the material's restitution, as for discs, whatever the curvature;
//   - a tilted ellipse bouncing elastically off a floor: the energy ledger books nothing as
//     dissipated (the elastic normal force turns it, and that work is the elastic energy's) and
//     its balance closes;
//   - an ellipse resting on its flat side on a floor, tilted a little and let go, rocks about
//     that rest at the frequency of a rigid ellipse rolling without slip,
//     w^2 = m g (a^2 - b^2) / b / (I + m b^2).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/run/simulation.hpp"
#include "core/shape/superellipse.hpp"
#include "core/step/diagnostics.hpp"
#include "support/scenes.hpp"

namespace dem2d {
namespace {

using testing_support::make_material;
using testing_support::segment;

ParticleSpec superellipse(double a, double b, double n, Vec2 x, Vec2 v, double angle) {
  ParticleSpec p;
  p.material = "steel";
  p.shape = ParticleShape::kSuperellipse;
  p.semi_a = a;
  p.semi_b = b;
  p.exponent = n;
  p.position = x;
  p.velocity = v;
  p.angle = angle;
  return p;
}

// Steel-like bodies of restitution e and sliding friction mu, no rolling resistance, the step
// chosen by the program.
Scene shape_scene(double e, double mu, Vec2 gravity) {
  Scene s;
  s.deck_path = "test";
  s.materials.push_back(make_material("steel", 7800, 2e9, 0.3, e, mu, 0.0));
  s.contact.rolling = RollingModelKind::kNone;
  s.run.gravity = gravity;
  s.run.dt_auto = true;
  return s;
}

// Two equal bodies at +-x0 along the lab's x approach at +-v; the restitution from their speeds
// once apart.
double head_on_restitution(double a, double b, double n, double angle) {
  Scene s = shape_scene(0.5, 0.3, {0.0, 0.0});
  const double x0 = 1.2 * std::max(a, b) * 1.5;
  s.particles.push_back(superellipse(a, b, n, {-x0, 0.0}, {0.5, 0.0}, angle));
  s.particles.push_back(superellipse(a, b, n, {x0, 0.0}, {-0.5, 0.0}, angle));
  Simulation sim(s);
  bool touched = false;
  for (int k = 0; k < 2000000; ++k) {
    sim.step();
    const bool now = sim.last_totals().contacts > 0;
    touched = touched || now;
    if (touched && !now) break;
  }
  EXPECT_TRUE(touched);
  const ParticleStore& p = sim.particles();
  const std::size_t i = p.id[0] == 0 ? 0 : 1, j = 1 - i;
  EXPECT_NEAR(p.vel[i].y, 0.0, 1e-12);
  EXPECT_NEAR(p.omega[i], 0.0, 1e-9);
  return (p.vel[j].x - p.vel[i].x) / 1.0;
}

TEST(SuperEllipseDynamics, CentredHeadOnImpactsHaveTheMaterialsRestitution) {
  // Ellipses tip to tip (R* = b^2 / a / 2) and side to side (a^2 / b / 2), rounded squares
  // face to face (the capped radius): the damping's restitution holds for any R*.
  const double tips = head_on_restitution(0.02, 0.01, 2.0, 0.0);
  const double sides = head_on_restitution(0.02, 0.01, 2.0, 0.5 * std::numbers::pi);
  const double faces = head_on_restitution(0.015, 0.015, 8.0, 0.0);
  std::printf("restitution 0.5: tips %.5f, sides %.5f, faces %.5f\n", tips, sides, faces);
  EXPECT_NEAR(tips, 0.5, 5e-3);
  EXPECT_NEAR(sides, 0.5, 5e-3);
  EXPECT_NEAR(faces, 0.5, 5e-3);
}

// An ellipse (aspect 0.5) tilted by 0.6 rad falls at 3 m/s onto a floor, elastic and without
// friction: the impact turns it fast (its kinetic energy goes into spin), books no dissipation,
// and kinetic + rotational + elastic energy is kept.
TEST(SuperEllipseDynamics, AnElasticTiltedEllipseBooksNoDissipationOnAFloor) {
  Scene s = shape_scene(1.0, 0.0, {0.0, 0.0});
  s.materials[0].youngs_modulus = 6e10;
  s.walls.push_back(segment({-0.2, 0.0}, {0.2, 0.0}, "steel"));
  s.particles.push_back(superellipse(0.05, 0.025, 2.0, {0.0, 0.06}, {0.0, -3.0}, 0.6));
  Simulation sim(s);
  const SeriesRow start = sim.diagnostics();
  bool touched = false;
  for (int k = 0; k < 1000000; ++k) {
    sim.step();
    const bool now = sim.last_totals().contacts > 0;
    touched = touched || now;
    if (touched && !now) break;
  }
  ASSERT_TRUE(touched);
  const SeriesRow end = sim.diagnostics();
  std::printf("rotational energy after %.4f of the start's, dissipated %.3g, balance %.3g\n",
              end.rotational_energy / start.kinetic_energy,
              end.dissipated_energy / start.kinetic_energy,
              (energy_balance(end) - energy_balance(start)) / start.kinetic_energy);
  EXPECT_GT(end.rotational_energy, 0.5 * start.kinetic_energy);
  EXPECT_NEAR(end.dissipated_energy, 0.0, 1e-9 * start.kinetic_energy);
  EXPECT_NEAR(energy_balance(end), energy_balance(start), 2e-4 * start.kinetic_energy);
}

// An ellipse (a = 2b) tilted by theta0 on its flat side, its lowest point on the floor, let go
// at rest: its angle oscillates at w^2 = m g (a^2 - b^2) / b / (I + m b^2), I = m (a^2 + b^2) / 5
// (the ellipsoid's), while friction keeps the contact from slipping.
TEST(SuperEllipseDynamics, AnEllipseRocksOnItsFlatSideAtTheRigidBodyFrequency) {
  const double a = 0.02, b = 0.01, theta0 = 0.02, g = 9.81;
  Scene s = shape_scene(0.9, 1.0, {0.0, -g});
  s.walls.push_back(segment({-0.2, 0.0}, {0.2, 0.0}, "steel"));
  const double h = std::sqrt(a * a * std::sin(theta0) * std::sin(theta0) +
                             b * b * std::cos(theta0) * std::cos(theta0));
  s.particles.push_back(superellipse(a, b, 2.0, {0.0, h}, {0.0, 0.0}, theta0));
  Simulation sim(s);
  const double m = sim.particles().mass[0];
  const double inertia = 1.0 / sim.particles().inv_inertia[0];
  EXPECT_NEAR(inertia, m * (a * a + b * b) / 5.0, 1e-12 * inertia);
  const double w = std::sqrt(m * g * (a * a - b * b) / b / (inertia + m * b * b));
  std::vector<double> crossings;  // the times theta passes through 0, interpolated
  double t_prev = sim.time(), th_prev = sim.particles().theta[0];
  while (sim.time() < 6.0 * 2.0 * std::numbers::pi / w) {
    sim.step();
    const double th = sim.particles().theta[0];
    if ((th_prev > 0.0) != (th > 0.0))
      crossings.push_back(t_prev + (sim.time() - t_prev) * th_prev / (th_prev - th));
    t_prev = sim.time();
    th_prev = th;
    ASSERT_LT(std::abs(th), 1.5 * theta0);
  }
  ASSERT_GE(crossings.size(), 10u);
  const double period =
      2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  std::printf("rocking period %.6f s, rigid ellipse %.6f s (%.2e)\n", period,
              2.0 * std::numbers::pi / w, period * w / (2.0 * std::numbers::pi) - 1.0);
  EXPECT_NEAR(period * w / (2.0 * std::numbers::pi), 1.0, 5e-3);
  // It rocks about the rest with its centre above the contact: no drift along the floor.
  EXPECT_LT(std::abs(sim.particles().pos[0].x), 0.02 * a);
}

}  // namespace
}  // namespace dem2d
