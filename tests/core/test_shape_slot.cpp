// The shape slot of the force kernel (core/shape/disc.hpp, core/contact/contact_kernel.hpp) for a
// shape whose contact arms leave the normal and that keeps history of its own. Two test shapes:
//   - the disc sent through the general path (vector arms r n, a history slot counting the steps
//     in contact): it must give the disc's own path to rounding, on pairs and walls, with each
//     contact law, rolling model and the release of the linear law's springs;
//   - an eccentric disc (centre of mass off the disc's centre), whose arms truly leave the
//     normal: a pair collision with friction keeps linear and angular momentum about the origin
//     to rounding (torques arm x force about one contact point), an elastic frictionless one
//     keeps kinetic energy to O(dt^2) (surface velocities v + w x arm), and a drop on a floor
//     turns translation into spin while keeping m g y + kinetic energy.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <type_traits>
#include <vector>

#include "core/contact/kernel_factory.hpp"
#include "core/contact/neighbors.hpp"
#include "support/kernel_bodies.hpp"
#include "support/scenes.hpp"

namespace dem2d {
namespace {

using testing_support::make_material;
using testing_support::rigid_wall_material;
using testing_support::segment;

// The disc through the general path: the same geometry, its arms as vectors, and one slot of
// its own counting the steps a contact has lasted.
struct CountingDisc : Disc {
  static constexpr bool kArmsAlongNormal = false;
  static constexpr std::array<HistorySlot, 1> kHistory{
      {{"steps_in_contact", "1", "steps this contact has lasted (test shape)"}}};

  template <class T>
  static PairContactT<T> pair(const PairInputT<T>& in, const std::array<T, 1>& old,
                              std::array<T, 1>& fresh) {
    PairContactT<T> g = Disc::pair(in.dx, in.dy, in.dist2, in.ri, in.rj);
    g.aix = in.ri * g.nx;
    g.aiy = in.ri * g.ny;
    g.ajx = -in.rj * g.nx;
    g.ajy = -in.rj * g.ny;
    fresh[0] = old[0] + 1.0;
    return g;
  }
  static WallContact wall(const Walls& walls, int element, Vec2 x, double r, double /*theta*/,
                          const std::array<double, 1>& old, std::array<double, 1>& fresh) {
    WallContact c;
    c.g = Disc::wall(walls, element, x, r);
    c.arm = r * c.g.n;
    c.r_eff = r;
    fresh[0] = old[0] + 1.0;
    return c;
  }
};

// cos and sin lane by lane (a pack's own sin and cos trip -Werror=uninitialized in libstdc++).
template <class T, class F>
T per_lane(const T& x, F f) {
  if constexpr (std::is_same_v<T, double>)
    return f(x);
  else
    return T([&](auto l) { return f(x[l]); });
}

// A disc of radius a whose centre of mass sits kOffset a from its centre, along its angle. The
// store's radius is the bounding circle about the centre of mass, (1 + kOffset) a, so that the
// broad phase and the gather's first test need nothing else. Arms point from each centre of
// mass to one contact point (midway in the overlap).
struct EccentricDisc : CountingDisc {
  static constexpr double kOffset = 0.3;
  static double disc_radius(double bounding) { return bounding / (1.0 + kOffset); }

  template <class T>
  static PairContactT<T> pair(const PairInputT<T>& in, const std::array<T, 1>& old,
                              std::array<T, 1>& fresh) {
    using std::sqrt;
    const auto cos = [](const T& x) { return per_lane(x, [](double v) { return std::cos(v); }); };
    const auto sin = [](const T& x) { return per_lane(x, [](double v) { return std::sin(v); }); };
    const T ai = in.ri * (1.0 / (1.0 + kOffset)), aj = in.rj * (1.0 / (1.0 + kOffset));
    // The discs' centres from x_i.
    const T gix = kOffset * ai * cos(in.th_i), giy = kOffset * ai * sin(in.th_i);
    const T gjx = in.dx + kOffset * aj * cos(in.th_j), gjy = in.dy + kOffset * aj * sin(in.th_j);
    const T ddx = gjx - gix, ddy = gjy - giy;
    const T dist = sqrt(ddx * ddx + ddy * ddy);
    PairContactT<T> g;
    g.delta = ai + aj - dist;
    g.nx = ddx / dist;
    g.ny = ddy / dist;
    g.r_eff = ai * aj / (ai + aj);
    const T s = ai - 0.5 * g.delta;  // from disc i's centre to the contact point
    g.aix = gix + s * g.nx;
    g.aiy = giy + s * g.ny;
    g.ajx = g.aix - in.dx;
    g.ajy = g.aiy - in.dy;
    g.arm_i = s;
    g.arm_j = aj - 0.5 * g.delta;
    fresh[0] = old[0] + 1.0;
    return g;
  }
  static WallContact wall(const Walls& walls, int element, Vec2 x, double r, double theta,
                          const std::array<double, 1>& old, std::array<double, 1>& fresh) {
    const double a = disc_radius(r);
    const Vec2 e = kOffset * a * Vec2{std::cos(theta), std::sin(theta)};
    WallContact c;
    c.g = Disc::wall(walls, element, x + e, a);
    c.arm = c.g.point - x;
    c.r_eff = a;
    fresh[0] = old[0] + 1.0;
    return c;
  }
};

// Bodies and walls run by one kernel with velocity Verlet (support/kernel_bodies.hpp).
template <class Model, class Shape>
using Bodies = testing_support::KernelBodies<Model, Shape>;

// The shape's own slot (the last) of the first listed pair, 0 when none is listed.
double pair_steps(const PairList& pl) {
  for (std::size_t k = 0; k < pl.size(); ++k) return pl.history_of(k)[pl.width - 1];
  return 0.0;
}

// Steel balls, a steel floor at y = 0 when `floor`, the given law and rolling model.
Scene two_balls(ContactModelKind law, RollingModelKind rolling, double restitution, double mu_s,
                double mu_r, bool floor, Vec2 gravity) {
  Scene s = testing_support::contact_scene("shape slot", 2e-6, law, rolling, gravity);
  s.materials.push_back(make_material("steel", 7800.0, 2e11, 0.25, restitution, mu_s, mu_r));
  s.materials.push_back(rigid_wall_material(s.materials[0]));
  if (floor) s.walls = {segment({-1.0, 0.0}, {1.0, 0.0}, "rigid")};
  return s;
}

// An oblique collision of two spinning balls, the lower one sliding and spinning into the floor.
void add_oblique_pair(Scene& s, double r) {
  s.particles.push_back(testing_support::ball("steel", r, {0.0, r}, {0.4, -0.3}, 25.0));
  s.particles.push_back(
      testing_support::ball("steel", r, {2.05 * r, 1.4 * r}, {-1.1, -0.2}, -40.0));
}

template <class Law, class Rolling>
void expect_general_path_is_the_discs(ContactModelKind law, RollingModelKind rolling) {
  using Model = ContactModel<Law, Rolling, TrackNone, StepAsSeen>;
  Scene s = two_balls(law, rolling, 0.7, 0.4, 0.05, true, {0.0, -9.81});
  add_oblique_pair(s, 0.01);
  Bodies<Model, Disc> disc(s);
  Bodies<Model, CountingDisc> general(s);
  disc.forces();
  general.forces();
  double max_force = 0.0, max_torque = 0.0, max_steps = 0.0;
  int steps_in_contact = 0;
  for (int n = 0; n < 3000; ++n) {
    disc.step();
    general.step();
    ASSERT_EQ(disc.tot.contacts, general.tot.contacts) << "step " << n;
    for (std::size_t k = 0; k < 2; ++k) {
      max_force = std::max(max_force, norm(disc.p.force[k]));
      max_torque = std::max(max_torque, std::abs(disc.p.torque[k]));
      ASSERT_NEAR(general.p.force[k].x, disc.p.force[k].x, 1e-11 * max_force + 1e-300);
      ASSERT_NEAR(general.p.force[k].y, disc.p.force[k].y, 1e-11 * max_force + 1e-300);
      ASSERT_NEAR(general.p.torque[k], disc.p.torque[k], 1e-11 * max_torque + 1e-300);
    }
    // The shape's slot counts the steps the pair has been in contact, from zero at first touch.
    const double rsum = general.p.radius[0] + general.p.radius[1];
    const bool touching =
        general.pl.size() > 0 && !(norm2(general.p.pos[1] - general.p.pos[0]) >= rsum * rsum);
    steps_in_contact = touching ? steps_in_contact + 1 : 0;
    ASSERT_EQ(pair_steps(general.pl), steps_in_contact) << "step " << n;
    max_steps = std::max(max_steps, pair_steps(general.pl));
  }
  EXPECT_GT(max_force, 1.0) << "the bodies collided";
  EXPECT_GT(max_steps, 10.0) << "the pair stayed in contact for a while";
  EXPECT_NEAR(general.dissipated, disc.dissipated, 1e-9 * disc.dissipated);
  EXPECT_GT(disc.dissipated, 0.0);
}

TEST(ShapeSlot, TheDiscThroughTheGeneralPathIsTheDiscHertzMindlinEpsd) {
  expect_general_path_is_the_discs<HertzMindlin, RollingEpsd>(ContactModelKind::kHertzMindlin,
                                                              RollingModelKind::kEpsd);
}
TEST(ShapeSlot, TheDiscThroughTheGeneralPathIsTheDiscHertzMindlinConstantRolling) {
  expect_general_path_is_the_discs<HertzMindlin, RollingConstant>(ContactModelKind::kHertzMindlin,
                                                                  RollingModelKind::kConstant);
}
// The linear law books what its springs hold when a contact ends (kernel_release.hpp).
TEST(ShapeSlot, TheDiscThroughTheGeneralPathIsTheDiscLinearWithRelease) {
  expect_general_path_is_the_discs<LinearModel, RollingNone>(ContactModelKind::kLinear,
                                                             RollingModelKind::kNone);
}

using HertzModel = ContactModel<HertzMindlin, RollingNone, TrackNone, StepAsSeen>;

constexpr double kA = 0.01;  // the eccentric discs' radius (m)

// Body k an eccentric disc of radius kA at angle theta: mass of the sphere of radius kA,
// I = 2/5 m a^2 + m e^2 (the moment about the centre of mass of a sphere displaced by e; any
// positive value would do).
template <class B>
void make_eccentric(B& b, std::size_t k, double theta) {
  const double m = Disc::mass(kA, 7800.0), e = EccentricDisc::kOffset * kA;
  b.set_inertia(k, m, 0.4 * m * kA * kA + m * e * e);
  b.p.theta[k] = theta;
}

// Two eccentric discs, centres of mass 2.75 a apart, the discs' centres 2.19 a apart, closing
// obliquely and spinning.
Scene eccentric_pair(double restitution, double mu_s, double dt) {
  Scene s = two_balls(ContactModelKind::kHertzMindlin, RollingModelKind::kNone, restitution, mu_s,
                      0.0, false, {0.0, 0.0});
  s.run.dt = dt;
  const double rb = (1.0 + EccentricDisc::kOffset) * kA;
  s.particles.push_back(testing_support::ball("steel", rb, {0.0, 0.0}, {0.8, 0.1}, 30.0));
  s.particles.push_back(
      testing_support::ball("steel", rb, {2.6 * kA, 0.9 * kA}, {-0.6, -0.2}, -20.0));
  return s;
}

// Runs until the pair has touched and come apart; returns the steps in contact.
template <class B>
int collide(B& b) {
  b.forces();
  int in_contact = 0;
  for (int n = 0; n < 200000; ++n) {
    b.step();
    if (b.tot.contacts > 0) ++in_contact;
    if (in_contact > 0 && b.tot.contacts == 0) return in_contact;
  }
  return -1;
}

TEST(ShapeSlot, EccentricDiscsKeepMomentumAndAngularMomentumThroughAFrictionalImpact) {
  Bodies<HertzModel, EccentricDisc> b(eccentric_pair(0.6, 0.5, 2e-7));
  make_eccentric(b, 0, 0.2);
  make_eccentric(b, 1, 3.0);
  const Vec2 p0 = b.momentum();
  const double l0 = b.angular_momentum(), w0 = b.p.omega[0], e0 = b.kinetic();
  const int steps = collide(b);
  ASSERT_GT(steps, 20) << "they touched, for a while";
  // Scale of the terms summed: m |x| |v| + I |w| ~ 1e-4 here.
  const double m = b.p.mass[0], scale = m * 0.03 * 1.0 + b.inertia[0] * 30.0;
  EXPECT_NEAR(b.momentum().x, p0.x, 1e-13 * m);
  EXPECT_NEAR(b.momentum().y, p0.y, 1e-13 * m);
  EXPECT_NEAR(b.angular_momentum(), l0, 1e-12 * scale);
  EXPECT_GT(std::abs(b.p.omega[0] - w0), 1.0) << "the impact changed the spins";
  EXPECT_LT(b.kinetic(), e0) << "damping and friction took energy";
  // What the law books as dissipated (its dashpot and slip at the surface velocities v + w x arm)
  // is what the bodies lost, to first order in dt: 1.1e-3 of it at dt = 2e-7, 5.5e-4 at 1e-7.
  EXPECT_NEAR(b.kinetic() + b.dissipated, e0, 2e-3 * e0) << "the law's dissipation is the loss";
}

// Without friction and damping the impact is elastic: what the off-centre normal force turns
// into spin comes back, if the surface velocity the law sees is v + w x arm.
TEST(ShapeSlot, EccentricDiscsKeepKineticEnergyThroughAnElasticImpact) {
  Bodies<HertzModel, EccentricDisc> b(eccentric_pair(1.0, 0.0, 2e-7));
  make_eccentric(b, 0, 0.2);
  make_eccentric(b, 1, 3.0);
  const double e0 = b.kinetic(), w0 = b.p.omega[1], l0 = b.angular_momentum();
  ASSERT_GT(collide(b), 20);
  EXPECT_NEAR(b.kinetic(), e0, 1e-6 * e0);
  EXPECT_GT(std::abs(b.p.omega[1] - w0), 0.5) << "the normal force, off the centre, spun it";
  EXPECT_NEAR(b.angular_momentum(), l0, 1e-12 * (b.p.mass[0] * 0.03 + b.inertia[0] * 30.0));
}

// An eccentric disc falls on the floor with no spin: the floor's push, off its centre of mass,
// spins it; without friction and damping m g y + kinetic energy is kept through the bounce, and
// the shape's slot counts the wall contact's steps.
TEST(ShapeSlot, AnEccentricDiscBouncingOnTheFloorSpinsAndKeepsItsEnergy) {
  Scene s = two_balls(ContactModelKind::kHertzMindlin, RollingModelKind::kNone, 1.0, 0.0, 0.0, true,
                      {0.0, -9.81});
  s.run.dt = 2e-7;
  const double rb = (1.0 + EccentricDisc::kOffset) * kA;
  s.particles.push_back(testing_support::ball("steel", rb, {0.0, 1.4 * kA}, {0.0, -0.5}));
  Bodies<HertzModel, EccentricDisc> b(s);
  make_eccentric(b, 0, -1.2);  // the disc's centre below-right of the centre of mass
  const double m = b.p.mass[0];
  const auto energy = [&] { return b.kinetic() + m * 9.81 * b.p.pos[0].y; };
  b.forces();
  const double e0 = energy();
  int in_contact = 0, max_slot = 0;
  for (int n = 0; n < 40000; ++n) {
    b.step();
    const bool touching = b.tot.contacts > 0;
    in_contact = touching ? in_contact + 1 : 0;
    const int slot = b.wl.size() > 0 ? static_cast<int>(b.wl.history_of(0)[b.wl.width - 1]) : 0;
    ASSERT_EQ(slot, in_contact) << "step " << n;
    max_slot = std::max(max_slot, slot);
    if (max_slot > 0 && !touching) break;
  }
  EXPECT_GT(max_slot, 20) << "it bounced";
  EXPECT_GT(std::abs(b.p.omega[0]), 1.0) << "the push off its centre of mass spun it";
  EXPECT_GT(b.p.vel[0].y, 0.0) << "it left the floor";
  EXPECT_NEAR(energy(), e0, 1e-6 * b.kinetic());
}

}  // namespace
}  // namespace dem2d
