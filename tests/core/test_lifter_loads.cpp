// The load on each lifter bar (core/geometry/lifter_loads.hpp): a ball at rest on a bar's
// lifting face hands the bar its weight, split into the face's normal and the radial; the bars'
// torques add up to the drive's lifter torque; the sums do not depend on the order of the
// records (the gathered records of any rank count give the same bits). The shell's response to
// the same records (core/structure/shell.hpp): the resting ball's weight reaches the supports
// whole, per metre of depth, and bends the bar the way the ball pushes; in a turning charge the
// nodal loads add up to the wall loads at every step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "core/geometry/lifter_loads.hpp"
#include "core/run/simulation.hpp"
#include "core/structure/shell.hpp"
#include "support/scenes.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::ball;
using testing_support::thesis_drum_scene;
using testing_support::thesis_steel;

constexpr double kDeg = std::numbers::pi / 180.0;

// A still drum (radius 1 m, turned by `drum_angle`) with one bar 0.3 m high and 0.1 m wide at
// `bar_deg` degrees from the bottom, counter-clockwise; a ball of radius 0.05 m resting on the
// bar's counter-clockwise (lifting) face, half way up it, clear of the shell (it falls onto
// the face from 0.1 mm). Friction and
// rolling resistance hold it on the tilted face.
Scene ball_on_a_bar(double bar_deg, double drum_angle) {
  Scene s;
  s.deck_path = "test";
  MaterialSpec m = thesis_steel(0.3);
  m.youngs_modulus = 2.0e8;
  m.shear_modulus = 8.0e7;
  m.sliding_friction = 0.6;
  m.rolling_friction = 0.4;
  s.materials.push_back(m);
  s.run.dt_auto = true;
  s.drum.present = true;
  s.drum.radius = 1.0;
  s.drum.speed = 0.0;
  s.drum.ramp_time = 0.0;
  s.drum.angle = drum_angle;
  s.drum.material = "steel";
  LifterSpec l;
  l.count = 1;
  l.height = 0.3;
  l.width = 0.1;
  l.angle = (bar_deg - 90.0) * kDeg - drum_angle;  // lab direction: -90 deg + bar_deg
  s.drum.lifters.push_back(l);
  const double theta = (bar_deg - 90.0) * kDeg;
  const Vec2 radial{std::cos(theta), std::sin(theta)};
  const double r = 0.05;
  s.particles.push_back(ball("steel", r, 0.85 * radial + (0.05 + r + 1e-4) * perp(radial)));
  return s;
}

TEST(LifterLoads, ABallAtRestOnALiftingFaceHandsTheBarItsWeightAlongTheFaceAndTheRadius) {
  for (const double bar_deg : {80.0, 100.0}) {
    Simulation sim(ball_on_a_bar(bar_deg, 0.7));
    sim.run_until(1.5);
    const ParticleStore& p = sim.particles();
    ASSERT_EQ(p.n_owned(), 1u);
    const double m = p.mass[0], weight = m * 9.81;
    ASSERT_LT(norm(p.vel[0]), 1e-5) << "the ball has settled on the face";
    const LifterBars bars(sim.scene(), sim.walls());
    ASSERT_EQ(bars.size(), 1u);
    EXPECT_NEAR(bars.angle_deg(0, sim.walls()), bar_deg, 1e-9);
    const std::vector<LifterContact> contacts =
        bars.contacts(sim.contacts().wall_loads(), p, sim.walls());
    ASSERT_EQ(contacts.size(), 1u) << "the ball touches the lifting face alone";
    ASSERT_EQ(sim.contacts().wall_loads().size(), 1u) << "and not the shell";
    const LifterLoad load = bars.sum(contacts, sim.walls()).at(0);
    // The ball presses its weight m g (0, -1) on the bar: along the face's normal (the
    // tangential, counter-clockwise) it presses against the lifting face, m g cos(90 - a) with
    // a the bar's angle from the bottom; along the radius it pushes outward below the
    // horizontal (a < 90) and inward above it: m g cos(a).
    const double a = bar_deg * kDeg;
    std::cout << "[ lifter loads ] bar at " << bar_deg << " deg: normal " << load.normal
              << " N (weight x sin a = " << weight * std::sin(a) << "), radial " << load.radial
              << " N (weight x cos a = " << weight * std::cos(a) << ")\n";
    EXPECT_NEAR(load.normal, weight * std::sin(a), 1e-4 * weight);
    EXPECT_NEAR(load.radial, weight * std::cos(a), 1e-4 * weight);
    EXPECT_EQ(load.contacts, 1);
    EXPECT_EQ(load.torque, sim.last_totals().lifter_torque);
  }
}

TEST(LifterLoads, AnglesAreFromTheBottomInTheDrumsSenseOfRotation) {
  Scene s = ball_on_a_bar(30.0, 0.0);
  s.particles.clear();
  s.drum.speed = 1.0;
  {
    Walls walls(s);
    const LifterBars bars(s, walls);
    EXPECT_NEAR(bars.angle_deg(0, walls), 30.0, 1e-12);
    // A quarter turn later, counter-clockwise: 120 degrees.
    walls.update(0.5 * std::numbers::pi);
    EXPECT_NEAR(bars.angle_deg(0, walls), 120.0, 1e-9);
    const Vec2 t = bars.tangential(0, walls), r = bars.radial(0, walls);
    EXPECT_NEAR(cross(r, t), 1.0, 1e-15) << "counter-clockwise of the radial";
  }
  s.drum.speed = -1.0;  // clockwise: the same bar is at 330 degrees, read clockwise
  Walls walls(s);
  const LifterBars bars(s, walls);
  EXPECT_NEAR(bars.angle_deg(0, walls), 330.0, 1e-9);
  walls.update(0.5 * std::numbers::pi);
  EXPECT_NEAR(bars.angle_deg(0, walls), 60.0, 1e-9);
  EXPECT_NEAR(cross(bars.radial(0, walls), bars.tangential(0, walls)), -1.0, 1e-15);
}

// 150 thesis balls in a drum turning at 1.8 rad/s with 12 bars 0.2 m high and 0.1 m wide.
Scene lifting_scene() {
  Scene s = thesis_drum_scene(150, 1.8, 0, 0.1);
  LifterSpec l;
  l.count = 12;
  l.height = 0.2;
  l.width = 0.1;
  s.drum.lifters.push_back(l);
  return s;
}

// The lifting scene after 1.2 s.
Simulation& lifting_charge() {
  static Simulation* sim = [] {
    auto* out = new Simulation(lifting_scene());
    out->run_until(1.2);
    return out;
  }();
  return *sim;
}

TEST(LifterLoads, TheBarsTorquesAddUpToTheLifterTorque) {
  Simulation& sim = lifting_charge();
  const LifterBars bars(sim.scene(), sim.walls());
  ASSERT_EQ(bars.size(), 12u);
  const std::vector<LifterContact> contacts =
      bars.contacts(sim.contacts().wall_loads(), sim.particles(), sim.walls());
  ASSERT_GT(contacts.size(), 3u) << "the bars carry some of the charge";
  const std::vector<LifterLoad> loads = bars.sum(contacts, sim.walls());
  double torque = 0.0, scale = 0.0;
  std::int64_t count = 0;
  for (const LifterLoad& l : loads) {
    torque += l.torque;
    scale += std::abs(l.torque);
    count += l.contacts;
  }
  for (const LifterContact& c : contacts) {
    EXPECT_EQ(c.bar, bars.bar_of(c.element));
    EXPECT_EQ(sim.walls().elements()[c.element].part, WallPart::kLifter);
  }
  EXPECT_EQ(count, static_cast<std::int64_t>(contacts.size()));
  const double lifter_torque = sim.last_totals().lifter_torque;
  std::cout << "[ lifter loads ] " << contacts.size() << " contacts on the bars; torques " << torque
            << " N m, lifter torque " << lifter_torque << " N m\n";
  EXPECT_NE(lifter_torque, 0.0);
  EXPECT_NEAR(torque, lifter_torque, 1e-12 * scale);
  // The bars lift: the charge presses on their lifting faces.
  double normal = 0.0;
  for (const LifterLoad& l : loads) normal += l.normal;
  EXPECT_GT(normal, 0.0);
}

TEST(LifterLoads, TheSumsDoNotDependOnTheRecordsOrder) {
  Simulation& sim = lifting_charge();
  const LifterBars bars(sim.scene(), sim.walls());
  std::vector<LifterContact> contacts =
      bars.contacts(sim.contacts().wall_loads(), sim.particles(), sim.walls());
  const std::vector<LifterLoad> in_order = bars.sum(contacts, sim.walls());
  // As three ranks would hand them over: blocks, each in its own order, then shuffled.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(contacts.begin(), contacts.end(), rng);
    const std::vector<LifterLoad> shuffled = bars.sum(contacts, sim.walls());
    ASSERT_EQ(shuffled.size(), in_order.size());
    for (std::size_t b = 0; b < in_order.size(); ++b) {
      EXPECT_EQ(shuffled[b].normal, in_order[b].normal) << "bar " << b;
      EXPECT_EQ(shuffled[b].radial, in_order[b].radial) << "bar " << b;
      EXPECT_EQ(shuffled[b].torque, in_order[b].torque) << "bar " << b;
      EXPECT_EQ(shuffled[b].contacts, in_order[b].contacts) << "bar " << b;
      EXPECT_EQ(shuffled[b].angle_deg, in_order[b].angle_deg) << "bar " << b;
    }
  }
}

TEST(LifterLoads, NoBarsWithoutLifters) {
  const Scene s = thesis_drum_scene(10, 1.0, 0);
  const Walls walls(s);
  const LifterBars bars(s, walls);
  EXPECT_TRUE(bars.empty());
  EXPECT_EQ(bars.bar_of(0), -1);
}

// The shell of the scenes above: a 50 mm steel ring (E as the balls'), 0.1 m of depth.
void add_shell(Scene& s) {
  s.shell.present = true;
  s.shell.thickness = 0.05;
  s.shell.depth = 0.1;
}

TEST(ShellResponse, ABallAtRestOnALiftingFaceLoadsTheSupportsWithItsWeightAndBendsTheBarBack) {
  for (const double bar_deg : {80.0, 100.0}) {
    Scene scene = ball_on_a_bar(bar_deg, 0.7);
    add_shell(scene);
    Simulation sim(scene);
    sim.run_until(1.5);
    const ParticleStore& p = sim.particles();
    const double weight = p.mass[0] * 9.81;
    ASSERT_LT(norm(p.vel[0]), 1e-5) << "the ball has settled on the face";
    const Shell shell(sim.scene(), sim.walls());
    const ShellResponse r = shell.respond(sim.contacts().wall_loads(), sim.walls(), true);
    ASSERT_EQ(r.records, 1u);
    ASSERT_EQ(r.bars.size(), 1u);
    // The weight in the drum frame (turned by the drum's angle 0.7), per metre of depth.
    const Vec2 w = rotate(Vec2{0.0, -weight / 0.1}, -0.7);
    std::cout << "[ shell ] bar at " << bar_deg << " deg: load " << r.applied.x << ", "
              << r.applied.y << " N/m (weight " << w.x << ", " << w.y << "), tip "
              << r.bars[0].tip_deflection << " m, root stress " << r.bars[0].root_stress << " Pa\n";
    EXPECT_LT(norm(r.applied - w), 1e-4 * norm(w));
    EXPECT_LT(norm(r.nodal - r.applied), 1e-13 * norm(w)) << "the nodal loads are the load";
    EXPECT_LT(norm(r.reaction + r.nodal), 1e-9 * norm(w)) << "the supports carry it all";
    // The ball presses the lifting face against the drum's sense of rotation (counter-
    // clockwise here): the bar's tip moves that way, and its root is stressed.
    EXPECT_GT(r.bars[0].tip_deflection, 0.0);
    EXPECT_GT(r.bars[0].root_stress, 0.0);
    EXPECT_GE(r.max_displacement, r.bars[0].tip_deflection);
  }
}

TEST(ShellResponse, TheNodalLoadsAddUpToTheWallLoadsAtEveryStep) {
  Scene s = lifting_scene();
  add_shell(s);
  s.shell.thickness = 0.1;
  Simulation sim(s);
  sim.run_until(0.8);
  const Shell shell(sim.scene(), sim.walls());
  double worst = 0.0;
  std::size_t most = 0;
  for (int step = 0; step < 50; ++step) {
    sim.step();
    const std::span<const WallLoad> loads = sim.contacts().wall_loads();
    const ShellResponse r = shell.respond(loads, sim.walls(), true);
    // The records' forces on the walls, summed here in the lab frame and turned to the drum's.
    Vec2 lab{};
    for (const WallLoad& w : loads) lab -= w.force;
    const Vec2 applied = rotate(lab, -sim.walls().drum_angle()) * (1.0 / 0.1);
    ASSERT_EQ(r.records, loads.size()) << "every record is on the shell or a bar";
    ASSERT_LT(norm(r.applied - applied), 1e-12 * norm(applied)) << "step " << step;
    worst = std::max(worst, norm(r.nodal - r.applied) / norm(r.applied));
    ASSERT_LT(norm(r.reaction + r.nodal), 1e-9 * norm(r.applied)) << "step " << step;
    most = std::max(most, r.records);
  }
  std::cout << "[ shell ] 50 steps, up to " << most << " records: nodal loads against wall loads "
            << worst << " (relative)\n";
  EXPECT_GT(most, 20u);
  EXPECT_LT(worst, 1e-13);
}

TEST(ShellResponse, TheShellsOwnMaterialSetsNoContactTime) {
  // The shell's finite elements take a stiff liner steel no particle and no wall has: the run's
  // automatic dt stays the charge's (a wall of that material would shorten it 1.3-fold).
  Scene plain = ball_on_a_bar(80.0, 0.0);
  Scene shelled = plain;
  add_shell(shelled);
  MaterialSpec liner = plain.materials[0];
  liner.name = "liner";
  liner.youngs_modulus = 2.1e11;
  liner.shear_modulus = 8.1e10;
  shelled.materials.push_back(liner);
  shelled.shell.material = "liner";
  const Simulation a(plain), b(shelled);
  EXPECT_EQ(a.dt(), b.dt());
  Scene liner_walls = shelled;
  liner_walls.drum.material = "liner";
  EXPECT_LT(Simulation(liner_walls).dt(), 0.9 * a.dt()) << "a wall of it does set one";
}

}  // namespace
}  // namespace dem2d
