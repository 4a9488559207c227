// The superellipse as a particle shape of the force kernel (core/shape/superellipse_shape.hpp):
//   - a = b, n = 2 superellipses give the disc kernel's forces and torques, step by step, for an
//     oblique spinning pair rolling onto a floor (the general path with the depth solve);
//   - an elastic ellipse bouncing in a box of four segments keeps its kinetic + rotational energy
//     over many impacts; two ellipses through a frictional impact keep momentum and angular
//     momentum to rounding;
//   - an ellipse dropped tilted on a floor with damping comes to rest on its flat side;
//   - the store's shape fields, masses and inertias; a run of ellipses twice gives the same bits.
// Particles are built in code (no deck keys yet): ParticleSpec's semi_a, semi_b, exponent, angle.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <vector>

#include "core/contact/kernel_factory.hpp"
#include "core/contact/neighbors.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/superellipse_shape.hpp"
#include "core/step/energy_ledger.hpp"
#include "support/kernel_bodies.hpp"
#include "support/scenes.hpp"

namespace dem2d {
namespace {

using testing_support::make_material;
using testing_support::rigid_wall_material;
using testing_support::segment;

// Bodies and walls run by one kernel with velocity Verlet (support/kernel_bodies.hpp).
template <class Model, class Shape>
using Bodies = testing_support::KernelBodies<Model, Shape>;

// The disc through the general path with the superellipse's arm convention for pairs: both arms
// end at the contact point midway in the overlap, (r_i - delta/2) n from i and -(r_j - delta/2) n
// from j (a common point: the pair's torques keep angular momentum), and on walls at the body's
// deepest point r n (the disc's own).
struct MidwayDisc : Disc {
  static constexpr bool kArmsAlongNormal = false;
  static constexpr std::array<HistorySlot, 0> kHistory{};
  template <class T>
  static PairContactT<T> pair(const PairInputT<T>& in, const std::array<T, 0>&, std::array<T, 0>&) {
    PairContactT<T> g = Disc::pair(in.dx, in.dy, in.dist2, in.ri, in.rj);
    const T si = in.ri - 0.5 * g.delta, sj = in.rj - 0.5 * g.delta;
    g.aix = si * g.nx;
    g.aiy = si * g.ny;
    g.ajx = -sj * g.nx;
    g.ajy = -sj * g.ny;
    return g;
  }
  static WallContact wall(const Walls& walls, int element, Vec2 x, double r, double,
                          const std::array<double, 0>&, std::array<double, 0>&) {
    WallContact c;
    c.g = Disc::wall(walls, element, x, r);
    c.arm = r * c.g.n;
    c.r_eff = r;
    return c;
  }
};

// The superellipse with its radius of curvature against walls held at a fixed value: the Hertz
// law's R* then does not change along a contact, and an elastic impact keeps the energy to
// O(dt^2) if the kernel's arms and surface velocities are right.
struct FixedCurvatureEllipse : SuperEllipseShape {
  static constexpr double kRadius = 0.01;
  static WallContact wall(const Walls& walls, int element, Vec2 x, double r, double theta,
                          const SuperEllipse& s, const std::array<double, 2>& old,
                          std::array<double, 2>& fresh) {
    WallContact c = SuperEllipseShape::wall(walls, element, x, r, theta, s, old, fresh);
    c.r_eff = kRadius;
    return c;
  }
};

// Steel (or a softer steel-dense material: E given), a rigid floor or box of that material.
Scene scene_of(double young, double restitution, double mu_s, double mu_r, double dt, Vec2 gravity,
               RollingModelKind rolling = RollingModelKind::kNone) {
  Scene s = testing_support::contact_scene("superellipse shape", dt,
                                           ContactModelKind::kHertzMindlin, rolling, gravity);
  s.materials.push_back(make_material("steel", 7800.0, young, 0.25, restitution, mu_s, mu_r));
  s.materials.push_back(rigid_wall_material(s.materials[0]));
  s.run.duration = 100.0;  // the tests step by hand
  return s;
}

ParticleSpec ellipse(double a, double b, Vec2 x, Vec2 v, double spin, double angle,
                     double n = 2.0) {
  ParticleSpec p = testing_support::ball("steel", bounding_radius({a, b, n}), x, v, spin);
  p.semi_a = a;
  p.semi_b = b;
  p.exponent = n;
  p.angle = angle;
  return p;
}

// The largest differences of forces and torques between two runs, relative to the largest
// force and torque of the first.
struct Gap {
  double max_force = 0.0, max_torque = 0.0, force = 0.0, torque = 0.0;
  template <class A, class B>
  void add(const A& a, const B& b) {
    for (std::size_t k = 0; k < a.p.size(); ++k) {
      max_force = std::max(max_force, norm(a.p.force[k]));
      max_torque = std::max(max_torque, std::abs(a.p.torque[k]));
      force = std::max(force, norm(b.p.force[k] - a.p.force[k]));
      torque = std::max(torque, std::abs(b.p.torque[k] - a.p.torque[k]));
    }
  }
  double rel_force() const { return force / max_force; }
  double rel_torque() const { return torque / max_torque; }
};

// An oblique collision of two spinning balls, the lower one sliding and spinning onto the floor
// (test_shape_slot.cpp's scene). Round superellipses against (1) the disc through the general
// path with the superellipse's arm convention: the same forces and torques to the solve's
// tolerance; (2) the disc's own kernel, whose pair arms end at each body's own surface (r n, not
// the common contact point (r - delta/2) n): apart by O(delta / r).
template <class Law, class Rolling>
void expect_round_superellipses_are_discs(RollingModelKind rolling) {
  using Model = ContactModel<Law, Rolling, TrackNone, StepAsSeen>;
  Scene s = scene_of(2e11, 0.7, 0.4, 0.05, 2e-6, {0.0, -9.81}, rolling);
  s.walls = {segment({-1.0, 0.0}, {1.0, 0.0}, "rigid")};
  const double r = 0.01;
  s.particles.push_back(testing_support::ball("steel", r, {0.0, r}, {0.4, -0.3}, 25.0));
  s.particles.push_back(
      testing_support::ball("steel", r, {2.05 * r, 1.4 * r}, {-1.1, -0.2}, -40.0));
  Bodies<Model, Disc> disc(s, false);
  Bodies<Model, MidwayDisc> midway(s, false);
  Bodies<Model, SuperEllipseShape> shaped(s, true);
  ASSERT_EQ((*shaped.p.semi_a())[1], r);
  ASSERT_EQ((*shaped.p.exponent())[1], 2.0);
  SuperEllipseShape::reset_stats();
  disc.forces();
  midway.forces();
  shaped.forces();
  Gap same, disc_gap;
  int pair_steps = 0, wall_steps = 0;
  for (int n = 0; n < 3000; ++n) {
    disc.step();
    midway.step();
    shaped.step();
    ASSERT_EQ(midway.tot.contacts, shaped.tot.contacts) << "step " << n;
    const double rsum = 2.0 * r;
    pair_steps += norm2(shaped.p.pos[1] - shaped.p.pos[0]) < rsum * rsum ? 1 : 0;
    wall_steps += shaped.wl.size() > 0 && shaped.p.pos[0].y < r ? 1 : 0;
    same.add(midway, shaped);
    disc_gap.add(disc, shaped);
  }
  const SuperEllipseShape::Stats& st = SuperEllipseShape::stats();
  std::printf(
      "round superellipses: vs the midway disc |dF|/F %.3g, |dT|/T %.3g; vs the disc's "
      "kernel |dF|/F %.3g, |dT|/T %.3g; %d pair steps, %d floor steps; %lld pair solves "
      "(%lld unconverged, %.2f depth evaluations each), %lld wall solves\n",
      same.rel_force(), same.rel_torque(), disc_gap.rel_force(), disc_gap.rel_torque(), pair_steps,
      wall_steps, static_cast<long long>(st.pair_solves),
      static_cast<long long>(st.pair_unconverged),
      static_cast<double>(st.pair_iterations) / std::max<double>(1.0, st.pair_solves),
      static_cast<long long>(st.wall_solves));
  EXPECT_GT(same.max_force, 1.0) << "the bodies collided";
  EXPECT_GT(pair_steps, 10) << "the pair stayed in contact for a while";
  EXPECT_GT(wall_steps, 20) << "the floor contact lasted";
  EXPECT_LT(same.rel_force(), 1e-8);
  EXPECT_LT(same.rel_torque(), 1e-8);
  EXPECT_LT(disc_gap.rel_force(), 1e-2);
  EXPECT_EQ(st.pair_unconverged, 0);
}

TEST(SuperEllipseShape, RoundOnesAreDiscsHertzMindlin) {
  expect_round_superellipses_are_discs<HertzMindlin, RollingNone>(RollingModelKind::kNone);
}
TEST(SuperEllipseShape, RoundOnesAreDiscsHertzMindlinEpsd) {
  expect_round_superellipses_are_discs<HertzMindlin, RollingEpsd>(RollingModelKind::kEpsd);
}

// A round superellipse spinning and sliding on the floor, then rolling: the disc's own kernel
// (the wall's arm is the disc's r n), to rounding.
TEST(SuperEllipseShape, ARoundOneOnTheFloorIsTheDisc) {
  using Model = ContactModel<HertzMindlin, RollingEpsd, TrackNone, StepAsSeen>;
  Scene s = scene_of(2e11, 0.7, 0.4, 0.05, 2e-6, {0.0, -9.81}, RollingModelKind::kEpsd);
  s.walls = {segment({-1.0, 0.0}, {1.0, 0.0}, "rigid")};
  const double r = 0.01;
  s.particles.push_back(testing_support::ball("steel", r, {0.0, r}, {0.6, 0.0}, 60.0));
  Bodies<Model, Disc> disc(s, false);
  Bodies<Model, SuperEllipseShape> shaped(s, true);
  disc.forces();
  shaped.forces();
  Gap gap;
  int in_contact = 0;
  for (int n = 0; n < 20000; ++n) {
    disc.step();
    shaped.step();
    ASSERT_EQ(disc.tot.contacts, shaped.tot.contacts) << "step " << n;
    in_contact += disc.tot.contacts;
    gap.add(disc, shaped);
  }
  std::printf(
      "round superellipse on the floor vs the disc: |dF|/F %.3g, |dT|/T %.3g, %d steps "
      "in contact, spin %.4f vs %.4f rad/s\n",
      gap.rel_force(), gap.rel_torque(), in_contact, shaped.p.omega[0], disc.p.omega[0]);
  EXPECT_GT(in_contact, 10000);
  // The geometry differs in the last bits each step (the support point's powers), and 20000
  // steps of a stiff sustained contact carry that into the state: 2.7e-10 at the end.
  EXPECT_LT(gap.rel_force(), 2e-9);
  EXPECT_LT(gap.rel_torque(), 2e-9);
}

TEST(SuperEllipseShape, TheStoreCarriesShapesAndTheirInertia) {
  ParticleStore disc_only;
  disc_only.add(0, 0, 0.01, 7800.0, {}, {}, 3.0);
  EXPECT_FALSE(disc_only.shaped());
  const std::size_t bytes = disc_only.bytes_per_particle();
  ParticleStore p;
  p.enable_shape();
  EXPECT_EQ(p.bytes_per_particle(), bytes + 4 * sizeof(double));  // a, b, n, elastic torque
  p.add(0, 0, 0.01, 7800.0, {}, {}, 3.0);
  p.add_shaped(1, 0, 0.02, 0.01, 2.0, 7800.0, {1.0, 0.0}, {}, 3.0, 0.4);
  p.add_shaped(2, 0, 0.01, 0.01, 2.0, 7800.0, {2.0, 0.0}, {}, 3.0, 0.0);
  // The disc is the store's disc, bit for bit.
  EXPECT_EQ(p.mass[0], disc_only.mass[0]);
  EXPECT_EQ(p.inv_inertia[0], disc_only.inv_inertia[0]);
  EXPECT_EQ((*p.semi_b())[0], 0.01);
  // The ellipse: a 3D ellipsoid a, b, c = b: m = 4/3 pi a b c rho, I_z = m (a^2 + b^2) / 5.
  const double m = 4.0 / 3.0 * std::numbers::pi * 0.02 * 0.01 * 0.01 * 7800.0;
  EXPECT_NEAR(p.mass[1], m, 1e-12 * m);
  EXPECT_NEAR(1.0 / p.inv_inertia[1], m * (0.02 * 0.02 + 0.01 * 0.01) / 5.0, 1e-12 * m * 1e-4);
  EXPECT_NEAR(p.radius[1], 0.02, 1e-15);
  EXPECT_EQ(p.theta[1], 0.4);
  // A round superellipse is the disc to rounding.
  EXPECT_NEAR(p.mass[2], p.mass[0], 1e-13 * p.mass[0]);
  EXPECT_NEAR(p.inv_inertia[2], p.inv_inertia[0], 1e-12 * p.inv_inertia[0]);
  // Rotational energy from each body's own inertia; a disc store's formula unchanged.
  EXPECT_NEAR(rotational_energy(p, 1), 0.5 * 9.0 / p.inv_inertia[1], 1e-15);
  EXPECT_EQ(rotational_energy(disc_only, 0), Disc::rotational_energy(disc_only.mass[0], 0.01, 3.0));
  // The fields are registered ones: migration, checkpoints and snapshots carry them.
  int named = 0;
  for (const FieldBase* f : p.fields())
    named += f->name() == "semi_axis_a" || f->name() == "semi_axis_b" || f->name() == "exponent";
  EXPECT_EQ(named, 3);
}

// Kinetic + rotational energy of a simulation's particles, from its diagnostics.
double kinetic(const Simulation& sim) {
  const SeriesRow r = sim.diagnostics();
  return r.kinetic_energy + r.rotational_energy;
}

Vec2 momentum(const ParticleStore& p) {
  Vec2 out{};
  for (std::size_t k = 0; k < p.n_owned(); ++k) out += p.mass[k] * p.vel[k];
  return out;
}
double angular_momentum(const ParticleStore& p) {
  double out = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    out += p.mass[k] * cross(p.pos[k], p.vel[k]) + p.omega[k] / p.inv_inertia[k];
  return out;
}

// A box [-h, h]^2 of four rigid segments.
void add_box(Scene& s, double h) {
  s.walls = {segment({-h, -h}, {h, -h}, "rigid"), segment({h, -h}, {h, h}, "rigid"),
             segment({h, h}, {-h, h}, "rigid"), segment({-h, h}, {-h, -h}, "rigid")};
}

// An elastic ellipse (aspect 2) spinning in a box of four segments: no damping (restitution 1),
// no friction, no rolling, no gravity; a softer steel for longer contacts (about 100 steps each).
// Returns the largest |E - E0| / E0 between impacts (kinetic + rotational with the ellipse's own
// inertia) and counts the impacts.
template <class Shape>
double box_energy_drift(double seconds, int& impacts, double& spin_range) {
  using Model = ContactModel<HertzMindlin, RollingNone, TrackNone, StepAsSeen>;
  Scene s = scene_of(2e9, 1.0, 0.0, 0.0, 1e-6, {0.0, 0.0});
  add_box(s, 0.05);
  s.particles.push_back(ellipse(0.02, 0.01, {0.0, 0.0}, {1.3, 0.9}, 35.0, 0.3));
  Bodies<Model, Shape> b(s, true);
  const auto energy = [&] {
    return 0.5 * b.p.mass[0] * norm2(b.p.vel[0]) + rotational_energy(b.p, 0);
  };
  b.forces();
  const double e0 = energy();
  double worst = 0.0, w_min = b.p.omega[0], w_max = b.p.omega[0];
  bool touching = false;
  impacts = 0;
  for (int n = 0; n * b.dt < seconds; ++n) {
    b.step();
    const bool now = b.tot.contacts > 0;
    impacts += now && !touching ? 1 : 0;
    touching = now;
    if (!touching) worst = std::max(worst, std::abs(energy() - e0));
    w_min = std::min(w_min, b.p.omega[0]);
    w_max = std::max(w_max, b.p.omega[0]);
  }
  spin_range = w_max - w_min;
  return worst / e0;
}

// With the curvature radius held fixed the impacts are elastic to O(dt^2): the kernel's arms
// and surface velocities v + w x arm are right.
TEST(SuperEllipseShape, AnElasticEllipseInABoxKeepsItsEnergyOverManyImpacts) {
  int impacts = 0;
  double spin_range = 0.0;
  SuperEllipseShape::reset_stats();
  const double drift = box_energy_drift<FixedCurvatureEllipse>(1.5, impacts, spin_range);
  std::printf(
      "ellipse in a box, fixed R*: %d impacts in 1.5 s, max |E - E0| / E0 %.3g, spin "
      "range %.1f rad/s, %lld wall solves (%lld unconverged)\n",
      impacts, drift, spin_range, static_cast<long long>(SuperEllipseShape::stats().wall_solves),
      static_cast<long long>(SuperEllipseShape::stats().wall_unconverged));
  EXPECT_GE(impacts, 40);
  EXPECT_GT(spin_range, 100.0) << "the impacts, off the centre, changed the spin";
  EXPECT_LT(drift, 2e-6);
  EXPECT_EQ(SuperEllipseShape::stats().wall_unconverged, 0);
}

// With the true curvature radius at the contact point, R* would change as the ellipse turns
// during a contact, and the Hertz force 4/3 E* sqrt(R*) delta^3/2 would not be the gradient of a
// potential (a drift of 4e-3 over 48 impacts in 1.5 s, the same for dt = 2e-6, 1e-6 and 5e-7).
// The kernel freezes R* at the contact's first step: each contact is then conservative, and the
// energy is kept as with a fixed R* (measured 1.9e-6 over 2 s).
TEST(SuperEllipseShape, AnElasticEllipseInABoxWithItsCurvatureKeepsItsEnergy) {
  int impacts = 0;
  double spin_range = 0.0;
  const double drift = box_energy_drift<SuperEllipseShape>(2.0, impacts, spin_range);
  std::printf(
      "ellipse in a box, R* from the curvature at each contact's first step: %d impacts in 2 s, "
      "max |E - E0| / E0 %.3g\n",
      impacts, drift);
  EXPECT_GE(impacts, 40);
  EXPECT_LT(drift, 5e-6);
}

TEST(SuperEllipseShape, TwoEllipsesKeepMomentumAndAngularMomentumThroughAFrictionalImpact) {
  Scene s = scene_of(2e11, 0.6, 0.5, 0.0, 2e-7, {0.0, 0.0});
  s.particles.push_back(ellipse(0.02, 0.01, {0.0, 0.0}, {0.8, 0.1}, 30.0, 0.2));
  s.particles.push_back(ellipse(0.015, 0.008, {0.045, 0.012}, {-0.6, -0.2}, -20.0, 1.9));
  SuperEllipseShape::reset_stats();
  Simulation sim(s);
  const ParticleStore& p = sim.particles();
  const Vec2 p0 = momentum(p);
  const double l0 = angular_momentum(p), e0 = kinetic(sim), w0 = p.omega[0];
  int in_contact = 0;
  for (int n = 0; n < 400000; ++n) {
    sim.step();
    if (sim.last_totals().contacts > 0) ++in_contact;
    if (in_contact > 0 && sim.last_totals().contacts == 0) break;
  }
  const double m = p.mass[0], scale = m * 0.05 * 1.0 + 30.0 / p.inv_inertia[0];
  std::printf(
      "frictional impact: %d steps in contact, dp/(m) = %.3g %.3g, dL/scale = %.3g, "
      "E/E0 = %.4f, %lld pair solves (%lld unconverged, %.2f depth evaluations each)\n",
      in_contact, (momentum(p).x - p0.x) / m, (momentum(p).y - p0.y) / m,
      (angular_momentum(p) - l0) / scale, kinetic(sim) / e0,
      static_cast<long long>(SuperEllipseShape::stats().pair_solves),
      static_cast<long long>(SuperEllipseShape::stats().pair_unconverged),
      static_cast<double>(SuperEllipseShape::stats().pair_iterations) /
          std::max<double>(1.0, SuperEllipseShape::stats().pair_solves));
  ASSERT_GT(in_contact, 20);
  EXPECT_NEAR(momentum(p).x, p0.x, 1e-13 * m);
  EXPECT_NEAR(momentum(p).y, p0.y, 1e-13 * m);
  EXPECT_NEAR(angular_momentum(p), l0, 1e-12 * scale);
  EXPECT_GT(std::abs(p.omega[0] - w0), 1.0) << "the impact changed the spins";
  EXPECT_LT(kinetic(sim), e0);
  EXPECT_EQ(SuperEllipseShape::stats().pair_unconverged, 0);
  // The histogram of depth evaluations per pair solve holds every solve, and its bins bound the
  // evaluations counted (each bin between its least and its most).
  const SuperEllipseShape::Stats& st = SuperEllipseShape::stats();
  constexpr std::array<std::int64_t, SuperEllipseShape::kEvaluationBins> least{1, 2, 3, 4,
                                                                               5, 9, 17};
  constexpr std::array<std::int64_t, SuperEllipseShape::kEvaluationBins> most{1, 2, 3, 4, 8, 16, 0};
  std::int64_t solves = 0, low = 0, high = 0;
  for (int b = 0; b < SuperEllipseShape::kEvaluationBins; ++b) {
    const std::int64_t k = st.pair_evaluation_bins[b];
    solves += k;
    low += least[b] * k;
    high += most[b] * k;
    EXPECT_EQ(SuperEllipseShape::bin_of(static_cast<int>(least[b])), b);
  }
  EXPECT_EQ(solves, st.pair_solves);
  EXPECT_EQ(st.pair_evaluation_bins[6], 0) << "no solve took 17 evaluations or more";
  EXPECT_LE(low, st.pair_iterations);
  EXPECT_GE(high, st.pair_iterations);
}

// Dropped tilted by 0.7 rad, it lands on its tip and rocks. Without rolling resistance the rocking
// lasts (the contact rolls without slipping, so neither the dashpots nor friction take energy:
// the mechanical energy stayed at 0.01191 J to 5 digits from 0.1 to 1.5 s); with the epsd model
// and mu_r = 0.02 it comes to rest, within the small angle the rolling spring can hold
// (mu_r R* F_n against m g times the contact point's offset, about 0.03 theta): R* is that of the
// contact's first step (frozen), at most the flat side's a^2 / b = 0.04 m, so theta < 0.027 rad.
TEST(SuperEllipseShape, ATiltedEllipseDroppedOnAFloorRestsOnItsFlatSide) {
  const double a = 0.02, b = 0.01;
  Scene s = scene_of(1e9, 0.3, 0.5, 0.02, 2e-6, {0.0, -9.81}, RollingModelKind::kEpsd);
  s.walls = {segment({-1.0, 0.0}, {1.0, 0.0}, "rigid")};
  s.particles.push_back(ellipse(a, b, {0.0, 0.04}, {0.0, 0.0}, 0.0, 0.7));
  Simulation sim(s);
  const ParticleStore& p = sim.particles();
  while (sim.time() < 2.0) sim.step();
  const double turns = p.theta[0] / std::numbers::pi;
  const double off = std::abs(turns - std::round(turns)) * std::numbers::pi;
  std::printf(
      "dropped ellipse at t = %.2f s: height %.6f m (b = %.3f), angle off horizontal "
      "%.2e rad, speed %.2e m/s, spin %.2e rad/s\n",
      sim.time(), p.pos[0].y, b, off, norm(p.vel[0]), p.omega[0]);
  EXPECT_NEAR(p.pos[0].y, b, 1e-3 * b);  // less its overlap under its weight (2e-6 m)
  EXPECT_LT(off, 0.02 * (a * a / b) / (a * a / b - b));
  EXPECT_LT(norm(p.vel[0]), 1e-9);
  EXPECT_LT(std::abs(p.omega[0]), 1e-9);
}

// A box of ellipses, rounded boxes and discs under gravity.
Scene mixed_box() {
  Scene s = scene_of(1e8, 0.5, 0.4, 0.0, 1e-5, {0.0, -9.81});
  add_box(s, 0.1);
  int k = 0;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 5; ++col, ++k) {
      const Vec2 x{-0.08 + 0.04 * col, -0.07 + 0.04 * row};
      const Vec2 v{0.3 * std::sin(1.7 * k), 0.2 * std::cos(2.3 * k)};
      if (k % 4 == 3)
        s.particles.push_back(testing_support::ball("steel", 0.01, x, v, 5.0));
      else
        s.particles.push_back(
            ellipse(0.016, 0.009, x, v, 3.0 * k, 0.5 * k, k % 4 == 2 ? 4.0 : 2.0));
    }
  return s;
}

TEST(SuperEllipseShape, ARunOfEllipsesTwiceGivesTheSameBits) {
  const Scene s = mixed_box();
  Simulation one(s), two(s);
  for (int n = 0; n < 40000; ++n) {
    one.step();
    two.step();
  }
  const ParticleStore &p = one.particles(), &q = two.particles();
  ASSERT_EQ(p.n_owned(), q.n_owned());
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    EXPECT_EQ(p.pos[k].x, q.pos[k].x);
    EXPECT_EQ(p.pos[k].y, q.pos[k].y);
    EXPECT_EQ(p.theta[k], q.theta[k]);
    EXPECT_EQ(p.omega[k], q.omega[k]);
  }
  EXPECT_GT(one.neighbor_builds(), 1);
  EXPECT_GT(one.last_totals().contacts, 10) << "they settled into a heap";
}

}  // namespace
}  // namespace dem2d
