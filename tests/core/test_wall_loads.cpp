// Wall loads (core/geometry/wall_loads.hpp): one record per wall contact, in the wall list's order,
// at a point of its element; a charge at rest in a still drum hands the walls its whole weight and
// its whole moment about the drum's axis (Newton's third law and the balance of moments: the pair
// forces cancel in both sums), and the drive's torque and power are computed from the records.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "core/geometry/wall_loads.hpp"
#include "core/run/simulation.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::thesis_drum_scene;

constexpr double kG = 9.81;

// 60 balls of the thesis settled in its drum (2.5 m), still, with 8 lifters 0.15 m high.
Simulation& settled_charge() {
  static Simulation* sim = [] {
    Scene s = thesis_drum_scene(60, 0.0, 0);
    s.drum.ramp_time = 0.0;
    LifterSpec l;
    l.count = 8;
    l.height = 0.15;
    l.width = 0.1;
    l.angle = 0.3;
    s.drum.lifters.push_back(l);
    auto* out = new Simulation(s);
    out->run_until(2.0);
    return out;
  }();
  return *sim;
}

// Distance from p to the element at the walls' current pose.
double distance_to_element(const Walls& walls, const WallElement& e, Vec2 p) {
  if (e.kind == WallKind::kCircle) return std::abs(norm(p - walls.circle_center(e)) - e.radius);
  const Vec2 ab = e.b - e.a;
  const double s = std::clamp(dot(p - e.a, ab) / norm2(ab), 0.0, 1.0);
  return norm(e.a + s * ab - p);
}

TEST(WallLoads, OneRecordPerWallContactAtAPointOfItsElementInListOrder) {
  Simulation& sim = settled_charge();
  const std::span<const WallLoad> loads = sim.contacts().wall_loads();
  const WallPairList& wl = sim.wall_pairs();
  const Walls& walls = sim.walls();
  ASSERT_GT(loads.size(), 5u) << "the charge rests on the shell";
  bool on_lifter = false;
  std::size_t cursor = 0;  // the records follow the wall list
  std::set<std::pair<std::int32_t, std::int32_t>> seen;
  for (const WallLoad& l : loads) {
    while (cursor < wl.size() &&
           !(wl.particle[cursor] == l.particle && wl.element[cursor] == l.element))
      ++cursor;
    ASSERT_LT(cursor, wl.size()) << "record of particle " << l.particle << " and element "
                                 << l.element << " out of the wall list's order";
    ++cursor;
    EXPECT_TRUE(seen.insert({l.particle, l.element}).second) << "one record per contact";
    const WallElement& e = walls.elements()[l.element];
    EXPECT_LT(distance_to_element(walls, e, l.point), 1e-12 * 2.5) << "element " << l.element;
    on_lifter |= e.part == WallPart::kLifter;
    // The wall pushes the particle away from itself: towards the particle's centre.
    EXPECT_GT(dot(l.force, sim.particles().pos[l.particle] - l.point), 0.0);
  }
  const EvaluationTotals& t = sim.last_totals();
  std::int64_t pair_contacts = 0;
  for (std::size_t k = 0; k < sim.pairs().size(); ++k) {
    const Vec2 d = sim.particles().pos[sim.pairs().j[k]] - sim.particles().pos[sim.pairs().i[k]];
    const double reach =
        sim.particles().radius[sim.pairs().i[k]] + sim.particles().radius[sim.pairs().j[k]];
    pair_contacts += norm2(d) < reach * reach ? 1 : 0;
  }
  EXPECT_EQ(static_cast<std::int64_t>(loads.size()) + pair_contacts, t.contacts);
  // The drive's figures are the records' (the engine's one consumer), bit for bit.
  const DriveLoads drive = drive_loads(loads, walls);
  EXPECT_EQ(drive.drum_torque, t.drum_torque);
  EXPECT_EQ(drive.lifter_torque, t.lifter_torque);
  EXPECT_EQ(drive.power, t.drive_power);
  EXPECT_EQ(t.drive_power, 0.0) << "a still drum does no work";
  std::cout << "[ wall loads ] " << loads.size() << " records (" << (on_lifter ? "some" : "none")
            << " on lifters), " << pair_contacts << " pair contacts\n";
}

TEST(WallLoads, AChargeAtRestHandsTheWallsItsWeightAndItsMoment) {
  Simulation& sim = settled_charge();
  const ParticleStore& p = sim.particles();
  const Vec2 c = sim.scene().drum.center;
  double mass = 0.0, moment_x = 0.0, kinetic = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    mass += p.mass[k];
    moment_x += p.mass[k] * (p.pos[k].x - c.x);
    kinetic += 0.5 * p.mass[k] * norm2(p.vel[k]);
  }
  ASSERT_LT(kinetic, 1e-6 * mass * kG * 0.1) << "the charge has settled";
  Vec2 force{};
  double moment = 0.0;
  for (const WallLoad& l : sim.contacts().wall_loads()) {
    force += l.force;
    moment += cross(l.point - c, l.force) + l.couple;
  }
  const double weight = mass * kG;
  std::cout << "[ wall loads ] at rest: walls' force on the charge (" << force.x << ", " << force.y
            << ") N against its weight " << weight << " N; moment " << moment
            << " N m against M g x_cm " << kG * moment_x << " N m\n";
  EXPECT_NEAR(force.x, 0.0, 1e-4 * weight);
  EXPECT_NEAR(force.y, weight, 1e-4 * weight);
  // The drum's torque on the charge balances gravity's moment about the axis (g = (0, -9.81)).
  EXPECT_NEAR(moment, kG * moment_x, 1e-3 * weight * 2.5);
  EXPECT_NEAR(sim.last_totals().drum_torque, moment, 1e-12 * weight * 2.5);
}

}  // namespace
}  // namespace dem2d
