// Mill analytics (core/mill/mill_analytics.hpp) on constructed states with known answers: a bed
// resting in a circular segment tilted at a known angle, one particle on the shell, a charge
// turning rigidly with the drum, the mirror image of a clockwise drum; the window's average
// power against a constant drive; the collision spectra against the closed-form peak energy of
// an elastic Hertz impact (all the kinetic energy of the normal motion is stored at the peak).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/mill/mill_analytics.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/disc.hpp"
#include "support/scenes.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

constexpr double kR = 2.5, kBall = 0.1;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr Vec2 kGravity{0.0, -9.81};

DrumSpec circle_drum(double speed = 1.0) {
  DrumSpec d;
  d.present = true;
  d.radius = kR;
  d.speed = speed;
  d.material = "steel";
  return d;
}

Walls walls_of(const DrumSpec& d) {
  Scene s;
  s.materials.push_back(testing_support::thesis_steel());
  s.drum = d;
  Walls w(s);
  w.update(10.0);  // past any ramp
  return w;
}

void add_ball(ParticleStore& p, Vec2 x, Vec2 v = {}, bool touching = true) {
  const std::size_t k = p.add(static_cast<std::int64_t>(p.size()), 0, kBall, 7800.0, x, v, 0.0);
  p.acc[k] = kGravity + (touching ? Vec2{0.0, 1.0} : Vec2{});
}

// Half the angle the row of balls along the shell spans under a chord at distance `depth` from
// the centre (their tops on the chord).
double ring_half_angle(double depth) { return std::acos((depth + kBall) / (kR - kBall)); }

// Balls filling the part of the drum below a chord at distance `depth` below the centre, the
// chord tilted by `tilt` (rad) so that it rises in the +x direction: a row touching each other
// along the shell, and a square lattice inside it.
void fill_tilted_segment(ParticleStore& p, double depth, double tilt) {
  const Vec2 up{-std::sin(tilt), std::cos(tilt)};  // the chord's normal, away from the bed
  const auto in_bed = [&](Vec2 c) { return dot(c, up) + kBall <= -depth; };
  // The row: from one end of the chord to the other (ball tops on the chord), evenly spaced
  // at most a diameter apart.
  const double rho = kR - kBall, half = ring_half_angle(depth);
  const int n = static_cast<int>(std::ceil(2 * half / (2 * std::asin(kBall / rho))));
  for (int k = 0; k <= n; ++k) {
    const double phi = tilt - half + 2 * half * k / n;
    add_ball(p, {rho * std::sin(phi), -rho * std::cos(phi)});
  }
  for (double x = -kR; x <= kR; x += 2 * kBall)
    for (double y = -kR; y <= kR; y += 2 * kBall) {
      const Vec2 c{x + kBall, y + kBall};
      if (norm(c) <= kR - 3 * kBall && in_bed(c)) add_ball(p, c);
    }
}

TEST(ChargeShape, TiltedBedGivesToeShoulderAndSurfaceAngle) {
  for (const double tilt_deg : {0.0, 20.0, 35.0}) {
    ParticleStore p;
    p.enable_last_contact();
    const double depth = 1.0;
    fill_tilted_segment(p, depth, tilt_deg * kDeg);
    const DrumSpec d = circle_drum();
    const ChargeShape c = measure_charge(p, walls_of(d), d, Domain{}, 0.0, kGravity);
    // The row's end balls reach asin(r / (R - r)) beyond their centres: toe and shoulder there,
    // to the shell's bin (0.5 degree).
    const double half = (ring_half_angle(depth) + std::asin(kBall / (kR - kBall))) / kDeg;
    EXPECT_NEAR(c.toe, tilt_deg - half, 0.5) << "tilt " << tilt_deg;
    EXPECT_NEAR(c.shoulder, tilt_deg + half, 0.5) << "tilt " << tilt_deg;
    EXPECT_NEAR(c.surface_angle, tilt_deg, 3.0) << "tilt " << tilt_deg;
    EXPECT_EQ(c.airborne_fraction, 0.0);
    EXPECT_EQ(c.corotating_fraction, 0.0);
    // The segment's centroid lies on its axis at distance 4 R sin^3(a) / (3 (2a - sin 2a)).
    const double a = std::acos(depth / kR);
    const double centroid = 4 * kR * std::pow(std::sin(a), 3) / (3 * (2 * a - std::sin(2 * a)));
    EXPECT_NEAR(c.com_x, centroid * std::sin(tilt_deg * kDeg), 0.05);
    EXPECT_NEAR(c.com_y, -centroid * std::cos(tilt_deg * kDeg), 0.05);
  }
}

TEST(ChargeShape, OneBallOnTheShellSpansItsOwnArc) {
  for (const double phi_deg : {-60.0, 0.0, 45.0, 170.0}) {
    ParticleStore p;
    const double rho = kR - kBall, phi = phi_deg * kDeg;
    add_ball(p, {rho * std::sin(phi), -rho * std::cos(phi)});
    const DrumSpec d = circle_drum();
    const ChargeShape c = measure_charge(p, walls_of(d), d, Domain{}, 0.0, kGravity);
    const double half = std::asin(kBall / rho) / kDeg;
    EXPECT_NEAR(c.toe, phi_deg - half, 0.5);
    EXPECT_NEAR(c.shoulder, phi_deg + half, 0.5);
    EXPECT_NEAR(c.shell_arc, 2 * half, 1.0);
  }
}

TEST(ChargeShape, BallsOnALifterRideTheShell) {
  DrumSpec d = circle_drum();
  LifterSpec l;
  l.count = 4;
  l.height = 0.15;
  l.width = 0.1;
  d.lifters.push_back(l);
  for (const bool on_lifter : {true, false}) {
    ParticleStore p;
    // On the lifter's top at 90 degrees (the rising side), or a radius higher.
    const double rho = kR - l.height - kBall - (on_lifter ? 0.0 : 2.1 * kBall);
    add_ball(p, {rho, 0.0});
    const ChargeShape c = measure_charge(p, walls_of(d), d, Domain{}, 0.0, kGravity);
    if (on_lifter) {
      EXPECT_NEAR(c.shoulder, 90.0 + std::asin(kBall / rho) / kDeg, 0.5);
    } else {
      EXPECT_EQ(c.shell_arc, 0.0);
    }
  }
}

// A row of balls on the shell from `from` to `to` (deg, centres), spaced one diameter apart
// along the shell, leaving out those whose centres lie within `gap` (deg) of a lifter at
// lifter0 + k * spacing; the shell layer of that moment.
ShellBits shell_row(double from, double to, double lifter0 = 0.0, double spacing = 0.0,
                    double gap = 0.0) {
  ParticleStore p;
  const double rho = kR - kBall, step = 2 * std::asin(kBall / rho) / kDeg;
  for (double phi = from; phi <= to + 1e-9; phi += step) {
    const double off = spacing > 0 ? std::remainder(phi - lifter0, spacing) : 1e9;
    if (std::abs(off) < gap) continue;
    add_ball(p, {rho * std::sin(phi * kDeg), -rho * std::cos(phi * kDeg)});
  }
  const DrumSpec d = circle_drum();
  return measure_charge(p, walls_of(d), d, Domain{}, 0.0, kGravity).shell;
}

// The time-averaged profile of a row from -38 to 137 degrees (Morrell's toe and shoulder of
// the defect's case) recovers its ends to the bin width, and so does a bare count profile.
TEST(ShellProfile, ToeAndShoulderOfAKnownArc) {
  const double rho = kR - kBall, half = std::asin(kBall / rho) / kDeg;
  MillWindow w(1.0);
  const ShellBits row = shell_row(-38.0 + half, 137.0);
  for (int k = 0; k < 10; ++k) {
    MillSample s;
    s.time = 0.1 * k;
    s.shell = row;
    w.add(s);
  }
  const double last = -38.0 + half + 2 * half * std::floor((175.0 - half) / (2 * half));
  EXPECT_NEAR(w.arc().toe, -38.0, 0.5);
  EXPECT_NEAR(w.arc().shoulder, last + half, 0.5);
  EXPECT_EQ(w.summary().toe, w.arc().toe);
  // Counts 10 over [-38, 137), 3 beyond: the level is 5, crossed at the bins' edges.
  std::vector<std::int64_t> counts(kShellBins, 3);
  for (int b = (180 - 38) * 2; b < (180 + 137) * 2; ++b) counts[static_cast<std::size_t>(b)] = 10;
  const ShellArc a = shell_arc(counts);
  EXPECT_NEAR(a.toe, -38.0, 0.25);
  EXPECT_NEAR(a.shoulder, 137.0, 0.25);
  EXPECT_NEAR(a.arc, 175.0, 0.5);
  counts.assign(kShellBins, 0);
  EXPECT_EQ(shell_arc(counts).arc, 0.0);
  EXPECT_TRUE(std::isnan(shell_arc(counts).toe));
  counts.assign(kShellBins, 2);
  EXPECT_EQ(shell_arc(counts).arc, 360.0);
  EXPECT_TRUE(std::isnan(shell_arc(counts).shoulder));
}

// Lifters every 15 degrees turning with the drum leave a ball-sized gap in the layer at each:
// every moment's covered arc breaks at them, the window's profile is one arc from end to end.
TEST(ShellProfile, GapsAtLiftersStillMakeOneArc) {
  const double rho = kR - kBall, half = std::asin(kBall / rho) / kDeg;
  MillWindow w(10.0);
  double widest_moment = 0.0;
  for (int k = 0; k < 30; ++k) {  // the lifters move 1 degree a row: two lifter spacings
    MillSample s;
    s.time = 0.01 * k;
    s.shell = shell_row(-40.0 + half, 100.0, 3.0 + k, 15.0, half);
    std::vector<std::int64_t> moment(kShellBins);
    for (int b = 0; b < kShellBins; ++b)
      moment[static_cast<std::size_t>(b)] = shell_bit(s.shell, b);
    widest_moment = std::max(widest_moment, shell_arc(moment).arc);
    w.add(s);
  }
  EXPECT_LT(widest_moment, 30.0) << "each moment's arc ends at a gap";
  const ShellArc a = w.arc();
  EXPECT_NEAR(a.toe, -40.0, 1.0);
  EXPECT_NEAR(a.shoulder, 100.0 + half, 2 * half);
  // A window of one row is that row's own arc.
  MillWindow one(0.005);
  for (int k = 0; k < 2; ++k) {
    MillSample s;
    s.time = 0.01 * k;
    s.shell = shell_row(-40.0 + half, 100.0, 3.0, 15.0, half);
    one.add(s);
  }
  EXPECT_EQ(one.samples().size(), 1u);
  EXPECT_LT(one.arc().arc, 30.0);
}

// The window's profile is the sum of the samples it holds: restoring them gives the same.
TEST(ShellProfile, RestoredWindowHasTheSameProfile) {
  MillWindow w(0.05);
  for (int k = 0; k < 12; ++k) {
    MillSample s;
    s.time = 0.01 * k;
    s.shell = shell_row(-30.0 + k, 60.0 + 2 * k);
    w.add(s);
  }
  MillWindow r(0.05);
  r.restore(w.samples());
  EXPECT_EQ(r.profile(), w.profile());
  EXPECT_EQ(w.samples().size(), 6u);
  std::int64_t top = 0;
  for (const std::int64_t c : w.profile()) top = std::max(top, c);
  EXPECT_EQ(top, 6);
}

TEST(MillNumbers, SliceIsTheMassWeightedMeanDiameter) {
  Scene s;
  s.drum = circle_drum();
  ParticleStore p;
  add_ball(p, {0.0, -1.0});
  add_ball(p, {0.5, -1.0});
  EXPECT_EQ(mill_numbers(s, charge_sizes(p, Domain{})).slice_thickness, 2 * kBall);
  // A ball of twice the diameter has 8 times the mass: (1 d + 1 d + 8 2d) / 10 = 1.8 d.
  p.add(2, 0, 2 * kBall, 7800.0, {-0.5, -1.0}, {}, 0.0);
  const ChargeSizes sizes = charge_sizes(p, Domain{});
  EXPECT_EQ(sizes.d_max, 4 * kBall);
  EXPECT_NEAR(mill_numbers(s, sizes).slice_thickness, 1.8 * 2 * kBall, 1e-12);
}

TEST(ChargeShape, ClockwiseDrumIsTheMirrorImage) {
  ParticleStore ccw, cw;
  ccw.enable_last_contact();
  cw.enable_last_contact();
  fill_tilted_segment(ccw, 1.2, 25.0 * kDeg);
  for (std::size_t k = 0; k < ccw.n_owned(); ++k) add_ball(cw, {-ccw.pos[k].x, ccw.pos[k].y});
  const DrumSpec a = circle_drum(1.0), b = circle_drum(-1.0);
  const ChargeShape s = measure_charge(ccw, walls_of(a), a, Domain{}, 0.0, kGravity);
  const ChargeShape m = measure_charge(cw, walls_of(b), b, Domain{}, 0.0, kGravity);
  EXPECT_DOUBLE_EQ(m.toe, s.toe);
  EXPECT_DOUBLE_EQ(m.shoulder, s.shoulder);
  EXPECT_NEAR(m.surface_angle, s.surface_angle, 1e-9);
  EXPECT_NEAR(m.com_x, -s.com_x, 1e-12);
}

TEST(ChargeShape, RigidlyTurningRingIsCentrifuging) {
  ParticleStore p;
  p.enable_last_contact();
  const double omega = 10.0, rho = kR - kBall;
  const int n = static_cast<int>(2 * std::numbers::pi * rho / (2 * kBall));
  for (int k = 0; k < n; ++k) {
    const double phi = 2 * std::numbers::pi * k / n;
    const Vec2 x{rho * std::cos(phi), rho * std::sin(phi)};
    add_ball(p, x, omega * perp(x));
  }
  DrumSpec d = circle_drum(omega);
  const ChargeShape c = measure_charge(p, walls_of(d), d, Domain{}, 0.0, kGravity);
  EXPECT_EQ(c.shell_arc, 360.0);
  EXPECT_TRUE(std::isnan(c.toe));
  EXPECT_NEAR(c.corotating_fraction, 0.5, 1.0 / n);
  EXPECT_NEAR(c.com_x, 0.0, 1e-9);
  WindowSummary w;
  w.span = 1.0;
  w.corotating = c.corotating_fraction;
  EXPECT_EQ(classify(w), Regime::kCentrifuging);
}

TEST(ChargeShape, FreeFlightNeedsNoContactForTheFlightTime) {
  ParticleStore p;
  p.enable_last_contact();
  add_ball(p, {0.0, 0.0}, {}, false);
  add_ball(p, {0.0, -kR + kBall}, {}, true);
  const DrumSpec d = circle_drum();
  clock_contacts(p, 1.0, kGravity);
  EXPECT_EQ((*p.last_contact())[1], 1.0);
  EXPECT_EQ((*p.last_contact())[0], 0.0);
  (*p.last_contact())[0] = 1.0 - 0.9 * kFlightTime;
  EXPECT_EQ(measure_charge(p, walls_of(d), d, Domain{}, 1.0, kGravity).airborne_fraction, 0.0);
  (*p.last_contact())[0] = 1.0 - kFlightTime;
  EXPECT_EQ(measure_charge(p, walls_of(d), d, Domain{}, 1.0, kGravity).airborne_fraction, 0.5);
}

TEST(MillWindow, AveragePowerIsTheWorkOverTheWindow) {
  MillWindow w(0.5);
  const double power = 7.0e4;
  for (int k = 0; k <= 2000; ++k) {
    const double t = k * 1e-3;
    // A drive whose power swings +-100 % every 10 ms about its mean.
    const double work = power * t + power * 0.01 / (2 * std::numbers::pi) *
                                        std::sin(2 * std::numbers::pi * t / 0.01);
    w.add({t, work, 0.1, 0.0, 30.0, -40.0, 60.0, 10.0 + std::sin(t)});
  }
  const WindowSummary s = w.summary();
  EXPECT_NEAR(s.span, 0.5, 1e-12);
  EXPECT_NEAR(s.power, power, 1e-6 * power);
  EXPECT_EQ(s.regime, Regime::kCataracting);
  EXPECT_NEAR(s.surface_angle, 30.0, 1e-9);
  // 10 + sin(t) over t in [1.5, 2]: the standard deviation of sin there.
  EXPECT_NEAR(s.charge_angle_std, 0.0272, 0.0005);
}

TEST(Regimes, CriterionOrder) {
  WindowSummary w;
  w.span = 1.0;
  w.toe = -40;
  w.shoulder = 40;
  w.surface_angle = 0;
  EXPECT_EQ(classify(w), Regime::kRolling);
  w.charge_angle_std = 3.0;
  EXPECT_EQ(classify(w), Regime::kSlumping);
  w.charge_angle_std = 0.5;
  w.shoulder = 52;  // the chord 6 degrees steeper than the surface
  EXPECT_EQ(classify(w), Regime::kCascading);
  w.airborne = 0.02;
  EXPECT_EQ(classify(w), Regime::kMixed);
  w.charge_angle_std = 5.0;  // a charge with flights swings too: still mixed
  EXPECT_EQ(classify(w), Regime::kMixed);
  w.airborne = 0.2;
  EXPECT_EQ(classify(w), Regime::kCataracting);
  w.corotating = 0.14;  // lifters carry some over the top
  EXPECT_EQ(classify(w), Regime::kCataracting);
  w.corotating = 0.2;
  EXPECT_EQ(classify(w), Regime::kCentrifuging);
}

TEST(CollisionSpectra, BinsAndClasses) {
  CollisionSpectra s({0.001, 0.002, 0.004}, {false, true});
  EXPECT_EQ(s.size_classes(), 4);
  EXPECT_EQ(s.size_class(0.0005), 0);
  EXPECT_EQ(s.size_class(0.001), 1);
  EXPECT_EQ(s.size_class(0.0039), 2);
  EXPECT_EQ(s.size_class(0.5), 3);
  EXPECT_EQ(CollisionSpectra::energy_bin(0.0), 0);
  EXPECT_EQ(CollisionSpectra::energy_bin(1e-13), 0);
  for (int b = 1; b < CollisionSpectra::kEnergyBins - 1; ++b) {
    const double lo = CollisionSpectra::energy_edge(b), hi = CollisionSpectra::energy_edge(b + 1);
    EXPECT_EQ(CollisionSpectra::energy_bin(lo * (1 + 1e-9)), b);
    EXPECT_EQ(CollisionSpectra::energy_bin(hi * (1 - 1e-9)), b);
  }
  EXPECT_EQ(CollisionSpectra::energy_bin(1e9), CollisionSpectra::kEnergyBins - 1);
}

// Two elastic steel balls head-on, and one dropped on a floor: each contact is booked once,
// when it ends, with its peak normal strain energy = the normal kinetic energy of the relative
// motion, 1/2 m* v^2 (m* = m/2 for the pair, m for the wall); the restitution is 1.
TEST(CollisionSpectra, ElasticImpactsBookTheirKineticEnergy) {
  Scene s;
  s.deck_path = "test";
  s.materials.push_back(testing_support::thesis_steel(1.0));
  s.materials[0].sliding_friction = 0.0;
  s.materials[0].rolling_friction = 0.0;
  s.output.collision_spectra = true;
  s.run.gravity = {0.0, 0.0};
  const double v = 1.0;
  for (const double x : {-0.2, 0.2})
    s.particles.push_back(testing_support::ball("steel", kBall, {x, 1.0}, {x < 0 ? v : -v, 0.0}));
  s.particles.push_back(testing_support::ball("steel", kBall, {3.0, 0.5}, {0.0, -v}));
  s.walls.push_back(testing_support::segment({2.0, 0.0}, {4.0, 0.0}, "steel"));
  Simulation sim(s);
  sim.run_until(0.6);
  const CollisionSpectra& spectra = *sim.spectra();
  const double m = Disc::mass(kBall, 7800.0);
  const auto booked = [&](ContactType t) {
    std::int64_t n = 0;
    for (int k = 0; k < spectra.size_classes(); ++k)
      for (int b = 0; b < CollisionSpectra::kEnergyBins; ++b)
        n += spectra.counts()[spectra.index(t, k, b)];
    const int k = spectra.size_class(2 * kBall);
    return std::pair{n, spectra.energies()[spectra.cell(t, k)]};
  };
  const auto [pairs, pair_energy] = booked(ContactType::kBallBall);
  const auto [walls, wall_energy] = booked(ContactType::kBallWall);
  EXPECT_EQ(pairs, 1);
  EXPECT_EQ(walls, 1);
  // The peak is the largest of the values at the ends of the steps.
  const double pair_exact = 0.5 * (m / 2) * (2 * v) * (2 * v), wall_exact = 0.5 * m * v * v;
  EXPECT_NEAR(pair_energy, pair_exact, 5e-3 * pair_exact);
  EXPECT_NEAR(wall_energy, wall_exact, 5e-3 * wall_exact);
}

}  // namespace
}  // namespace dem2d
