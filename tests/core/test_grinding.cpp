// Grinding (docs/models.md, "Grinding"; thesis T34-T36): the breakage
// law's statistics, the fragment law, conservation at a break, the sieve and the feed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>

#include "core/base/errors.hpp"
#include "core/contact/contact_models.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/disc.hpp"
#include "core/shape/superellipse.hpp"
#include "core/shape/superellipse_sizing.hpp"
#include "support/scenes.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::ball;
using testing_support::segment;

// The ore of the thesis's Table 1.
MaterialSpec thesis_ore() {
  MaterialSpec m;
  m.name = "ore";
  m.density = 4800.0;
  m.youngs_modulus = 6.0e10;
  m.poisson_ratio = 0.25;
  m.shear_modulus = 2.4e10;
  m.restitution = 0.73;
  m.sliding_friction = 0.1;
  return m;
}

// n ore spheres of radius r side by side above a floor, all moving down at v (no gravity):
// they strike the floor at the same instant with the same energy.
Scene impacts(int n, double r, double v, double strength) {
  Scene s;
  s.deck_path = "test";
  s.materials.push_back(thesis_ore());
  s.contact.rolling = RollingModelKind::kNone;
  s.run.gravity = {0.0, 0.0};
  s.run.dt_auto = true;
  s.run.seed = 7;
  for (int k = 0; k < n; ++k)
    s.particles.push_back(ball("ore", r, {3.0 * r * k, r + 1e-3}, {0.0, -v}));
  s.walls.push_back(segment({-r, 0.0}, {3.0 * r * n, 0.0}, "ore"));
  s.breakage.present = true;
  s.breakage.material = "ore";
  s.breakage.strength = strength;
  s.breakage.minimum_radius = 0.9 * r;  // fragments do not break again
  return s;
}

TEST(Grinding, BreakFractionOfEqualImpactsIsInItsBinomialBandAndFragmentsFollowTheirLaw) {
  const int n = 400;
  Simulation sim(impacts(n, 0.05, 1.0, 0.7));
  sim.run_until(0.004);  // one impact each (the contact lasts about 0.3 ms)
  const std::vector<BreakageRecord> breaks = sim.grinding()->take_breakages();
  ASSERT_GT(breaks.size(), 0u);
  // Every particle met the floor alike: one peak energy, one probability (T36).
  const double e = breaks.front().energy;
  for (const BreakageRecord& b : breaks) EXPECT_NEAR(b.energy, e, 1e-9 * e);
  const double p = 1.0 - std::exp(-0.7 * (e - 0.1));
  const double fraction = static_cast<double>(breaks.size()) / n;
  EXPECT_NEAR(fraction, p, 4.0 * std::sqrt(p * (1.0 - p) / n)) << "E = " << e << " J";
  // Survivors carry the damage E - E_min (T34).
  const ParticleStore& ps = sim.particles();
  int survivors = 0;
  for (std::size_t k = 0; k < ps.n_owned(); ++k) {
    if (ps.id[k] >= n) continue;
    ++survivors;
    EXPECT_NEAR((*ps.damage())[k], e - 0.1, 1e-9);
  }
  EXPECT_EQ(survivors + static_cast<int>(breaks.size()), n);
  // Fragment counts: normal law of mean 4 and sd 2/3, rounded and clipped to [2, 6].
  double mean = 0.0;
  for (const BreakageRecord& b : breaks) {
    EXPECT_GE(b.fragments, 2);
    EXPECT_LE(b.fragments, 6);
    mean += b.fragments / static_cast<double>(breaks.size());
  }
  EXPECT_NEAR(mean, 4.0, 4.0 * (2.0 / 3.0) / std::sqrt(static_cast<double>(breaks.size())));
}

// Two runs alike until the break: one whose ore cannot break (strength tiny) and one whose ore
// breaks at its first test. At the break the fragments hold the parent's mass and momentum and
// no more kinetic energy, and the energy balance holds through it.
TEST(Grinding, ABreakConservesMassAndMomentumAndCreatesNoEnergy) {
  Scene s = impacts(1, 0.05, 3.0, 1.0e9);
  s.particles[0].velocity = {0.7, -3.0};
  s.particles[0].spin = 20.0;
  Scene whole = s;
  whole.breakage.strength = 1.0e-30;
  Simulation breaks(s), keeps(whole);
  const double k0 = breaks.diagnostics().kinetic_energy;
  while (breaks.grinding()->totals().breakages == 0) {
    const SeriesRow before = breaks.diagnostics();
    const double kept_before = energy_balance(keeps.diagnostics());
    breaks.step();
    keeps.step();
    ASSERT_LT(breaks.time(), 0.01);
    if (breaks.grinding()->totals().breakages == 0) continue;
    const ParticleStore& f = breaks.particles();
    const ParticleStore& q = keeps.particles();
    double mass = 0.0, kinetic = 0.0;
    Vec2 momentum{};
    for (std::size_t k = 0; k < f.n_owned(); ++k) {
      mass += f.mass[k];
      momentum += f.mass[k] * f.vel[k];
      kinetic += 0.5 * f.mass[k] * norm2(f.vel[k]) +
                 0.5 * Disc::inertia(f.mass[k], f.radius[k]) * f.omega[k] * f.omega[k];
    }
    const double parent_kinetic =
        0.5 * q.mass[0] * norm2(q.vel[0]) +
        0.5 * Disc::inertia(q.mass[0], q.radius[0]) * q.omega[0] * q.omega[0];
    EXPECT_GE(f.n_owned(), 2u);
    EXPECT_NEAR(mass, q.mass[0], 1e-12 * q.mass[0]);
    EXPECT_NEAR(momentum.x, q.mass[0] * q.vel[0].x, 1e-12 * q.mass[0]);
    EXPECT_NEAR(momentum.y, q.mass[0] * q.vel[0].y, 1e-12 * q.mass[0]);
    EXPECT_LE(kinetic, parent_kinetic);
    const SeriesRow after = breaks.diagnostics();
    EXPECT_GE(after.dissipated_energy, before.dissipated_energy);  // the break released energy
    // The step's own integration error is the same in both runs; the break adds nothing to it.
    const double kept_step = energy_balance(keeps.diagnostics()) - kept_before;
    EXPECT_NEAR(energy_balance(after) - energy_balance(before), kept_step, 1e-9 * k0);
  }
}

// Superellipse ore (aspect 0.5, exponent 4, turned at random) strikes the floor and breaks: each
// parent's fragments are superellipses of its aspect and exponent, born turned as its long axis,
// of its mass in all; the mill's mass is kept and the energy balance holds (to first order in dt
// here: 1.5e-3 of the kinetic energy at the automatic step, 3.6e-4 at a quarter of it).
TEST(Grinding, ABrokenSuperellipseGivesFragmentsOfItsFormAndMass) {
  const int n = 30;
  Scene s = impacts(n, 0.05, 3.0, 1.0e9);
  s.contact.rolling = RollingModelKind::kEpsd;
  const SuperEllipse e = superellipse_of_size(0.04, 0.5, 4.0);
  for (int k = 0; k < n; ++k) {
    ParticleSpec& q = s.particles[static_cast<std::size_t>(k)];
    q.shape = ParticleShape::kSuperellipse;
    // Half of them with the long axis along the body's y (b > a).
    q.semi_a = k % 2 == 0 ? e.a : e.b;
    q.semi_b = k % 2 == 0 ? e.b : e.a;
    q.exponent = 4.0;
    q.angle = 0.37 * k;
    q.position = {0.2 * k, 0.1};  // clear of the floor and each other, whatever their angle
  }
  s.walls[0].to = {0.2 * n, 0.0};
  s.breakage.minimum_radius = 0.039;  // fragments do not break again
  Simulation sim(s);
  const double m0 = sim.diagnostics().mill_mass;
  const double b0 = energy_balance(sim.diagnostics()), k0 = sim.diagnostics().kinetic_energy;
  // Each body's long axis, as it turns, until it breaks.
  std::map<std::int64_t, double> long_axis;
  std::map<std::int64_t, bool> seen_fragment;
  const auto axis_of = [](const ParticleStore& p, std::size_t k) {
    return p.theta[k] + ((*p.semi_a())[k] < (*p.semi_b())[k] ? 0.5 * std::numbers::pi : 0.0);
  };
  std::map<std::int64_t, std::int64_t> parent_of;
  while (sim.time() < 0.03) {
    const ParticleStore& before = sim.particles();
    for (std::size_t k = 0; k < before.n_owned(); ++k)
      if (before.id[k] < n) long_axis[before.id[k]] = axis_of(before, k);
    sim.step();
    for (const FragmentRecord& f : sim.grinding()->take_fragments()) parent_of[f.id] = f.parent;
    const ParticleStore& p = sim.particles();
    for (std::size_t k = 0; k < p.n_owned(); ++k) {
      if (p.id[k] < n || seen_fragment[p.id[k]]) continue;
      seen_fragment[p.id[k]] = true;
      // Born in this step, turned as its parent's long axis a step before (and one step's turn).
      const double d =
          std::remainder(axis_of(p, k) - long_axis[parent_of.at(p.id[k])], std::numbers::pi);
      EXPECT_LT(std::abs(d), 1e-2) << "fragment " << p.id[k];
      const SuperEllipse f{(*p.semi_a())[k], (*p.semi_b())[k], (*p.exponent())[k]};
      EXPECT_NEAR(f.b / f.a, 0.5, 1e-15);
      EXPECT_EQ(f.n, 4.0);
      EXPECT_NEAR(p.mass[k], mass(f, 4800.0), 1e-14 * p.mass[k]);
    }
  }
  const std::vector<BreakageRecord> breaks = sim.grinding()->take_breakages();
  ASSERT_GT(breaks.size(), n / 2u);
  std::map<std::int64_t, double> born;
  for (const auto& [id, parent] : parent_of) {
    const ParticleStore& p = sim.particles();
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      if (p.id[k] == id) born[parent] += p.mass[k];
  }
  for (const BreakageRecord& r : breaks) {
    EXPECT_NEAR(born[r.parent], r.mass, 1e-13 * r.mass);
    EXPECT_NEAR(r.radius, 0.04, 1e-15);  // the volume-equivalent radius
    EXPECT_NEAR(r.mass, Disc::mass(0.04, 4800.0), 1e-13 * r.mass);
  }
  EXPECT_EQ(seen_fragment.size(), parent_of.size());
  const SeriesRow row = sim.diagnostics();
  EXPECT_NEAR(row.mill_mass, m0, 1e-12 * m0);
  EXPECT_NEAR(energy_balance(row) - b0, 0.0, 3e-3 * k0);
}

// Fragments overlap each other at birth and must not repel: without gravity and walls they
// move apart only by the parent's spin, force-free, and the pair's history ends when they part.
TEST(Grinding, BirthOverlapsGiveNoForceUntilTheBodiesPart) {
  Scene s = impacts(1, 0.05, 3.0, 1.0e9);
  s.particles[0].spin = 50.0;
  Simulation sim(s);
  while (sim.grinding()->totals().breakages == 0) sim.step();
  const ParticleStore& p = sim.particles();
  std::map<std::int64_t, Vec2> v0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) v0[p.id[k]] = p.vel[k];
  // Away from the floor the fragments fly force-free while they still overlap.
  sim.run_until(sim.time() + 0.002);
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    if (p.pos[k].y < p.radius[k] + 0.01) continue;  // still at the floor
    EXPECT_NEAR(norm(p.vel[k] - v0[p.id[k]]), 0.0, 1e-9) << "fragment " << p.id[k];
  }
  EXPECT_LT(sim.last_totals().max_overlap, 0.25);  // birth overlaps are not the guard's concern
}

TEST(Grinding, TheSieveRemovesOnlySmallOreInsideItsZone) {
  Scene s;
  s.deck_path = "test";
  s.materials = {thesis_ore(), testing_support::thesis_steel()};
  s.run.gravity = {0.0, 0.0};
  const auto add = [&s](const char* material, double r, Vec2 x) {
    s.particles.push_back(ball(material, r, x));
  };
  add("ore", 0.03, {0.0, 0.0});     // small ore inside: leaves
  add("ore", 0.03, {2.0, 0.0});     // small ore outside
  add("ore", 0.05, {0.3, 0.3});     // large ore inside
  add("steel", 0.03, {-0.3, 0.3});  // small steel inside
  s.sieve.present = true;
  s.sieve.material = "ore";
  s.sieve.aperture = 0.07;  // a diameter: the 6 cm ore passes, the 10 cm does not
  Simulation sim(s);
  const double m0 = sim.diagnostics().mill_mass;
  sim.step();
  const ParticleStore& p = sim.particles();
  ASSERT_EQ(p.n_owned(), 3u);
  for (std::size_t k = 0; k < p.n_owned(); ++k) EXPECT_NE(p.id[k], 0);
  const std::vector<ProductRecord> product = sim.grinding()->take_product();
  ASSERT_EQ(product.size(), 1u);
  EXPECT_EQ(product[0].id, 0);
  const SeriesRow r = sim.diagnostics();
  EXPECT_EQ(r.discharged_count, 1);
  EXPECT_DOUBLE_EQ(r.mill_mass + r.discharged_mass, m0);
}

TEST(Grinding, FedParticlesNeverOverlapAndTheMassBalanceHolds) {
  Scene s = testing_support::thesis_drum_scene(120, 1.5, 16);
  s.materials.push_back(thesis_ore());
  s.feed.present = true;
  s.feed.material = "ore";
  s.feed.period = 0.002;
  s.feed.radius_min = 0.05;
  s.feed.radius_max = 0.08;
  Simulation sim(s);
  const double m0 = sim.diagnostics().mill_mass;
  std::int64_t seen = 0;
  while (sim.time() < 0.1) {
    sim.step();
    const ParticleStore& p = sim.particles();
    const std::int64_t fed = sim.grinding()->totals().fed_count;
    if (fed == seen) continue;
    seen = fed;
    // The newest particle touches nothing and lies inside the drum.
    const auto newest = std::max_element(p.id.data(), p.id.data() + p.n_owned()) - p.id.data();
    const Vec2 x = p.pos[static_cast<std::size_t>(newest)];
    const double r = p.radius[static_cast<std::size_t>(newest)];
    EXPECT_LT(norm(x) + r, 2.5 * std::cos(std::numbers::pi / 16));
    for (std::size_t k = 0; k < p.n_owned(); ++k) {
      if (k == static_cast<std::size_t>(newest)) continue;
      EXPECT_GE(norm(p.pos[k] - x), p.radius[k] + r) << "fed particle " << p.id[newest];
    }
  }
  EXPECT_GE(seen, 45);
  const SeriesRow r = sim.diagnostics();
  EXPECT_NEAR(r.mill_mass, m0 + r.fed_mass, 1e-12 * m0);
}

// Damage accumulates over impacts (T34): an unbreakable ore sphere bounces between two walls of
// ore; after each contact its damage has grown by its share of that contact's peak strain
// energy less E_min. Against its own material the share is 1/2 (equal compliances).
TEST(Grinding, DamageAccumulatesOverImpacts) {
  Scene s = impacts(1, 0.05, 4.0, 1.0e-30);
  s.walls.push_back(segment({0.2, 0.3}, {-0.2, 0.3}, "ore"));  // a ceiling
  Simulation sim(s);
  const std::size_t slot = sim.contacts().history_offset("peak_energy");
  double expected = 0.0, peak = 0.0;
  int impacts_seen = 0;
  while (sim.time() < 0.4) {
    sim.step();
    const WallPairList& wl = sim.wall_pairs();
    double now = 0.0;
    for (std::size_t k = 0; k < wl.size(); ++k) now = std::max(now, wl.history_of(k)[slot]);
    if (now == 0.0 && peak > 0.0) {  // a contact ended: it was tested at its peak
      expected += 0.5 * peak - 0.1;
      ++impacts_seen;
      EXPECT_NEAR((*sim.particles().damage())[0], expected, 1e-9 * expected);
    }
    peak = now;
  }
  EXPECT_GE(impacts_seen, 4);
}

// The fragments fly apart by their parent's spin; once apart, their contact is gone with its
// birth overlap, and no force ever acted between them.
TEST(Grinding, BirthOverlapsEndWhenTheFragmentsPart) {
  Scene s = impacts(1, 0.05, 3.0, 1.0e9);
  s.particles[0].velocity = {0.0, 3.0};  // away from the floor: no other contact
  s.particles[0].position = {0.0, 0.5};
  s.particles[0].spin = 80.0;
  // A second, smaller sphere (below minimum_radius: it does not break) strikes it head-on.
  s.particles.push_back(ball("ore", 0.04, {0.0, 0.7}, {0.0, -3.0}));
  Simulation hit(s);
  while (hit.grinding()->totals().breakages == 0) {
    hit.step();
    ASSERT_LT(hit.time(), 0.1);
  }
  const std::size_t slot = hit.contacts().history_offset("birth_overlap");
  bool overlapped = false;
  for (int k = 0; k < 40000; ++k) {
    hit.step();
    bool any = false;
    for (std::size_t c = 0; c < hit.pairs().size(); ++c)
      any = any || hit.pairs().history_of(c)[slot] > 0.0;
    overlapped = overlapped || any;
    if (overlapped && !any) break;
  }
  EXPECT_TRUE(overlapped);
  for (std::size_t c = 0; c < hit.pairs().size(); ++c)
    EXPECT_EQ(hit.pairs().history_of(c)[slot], 0.0);
  // They parted: no pair of fragments overlaps now.
  const ParticleStore& p = hit.particles();
  for (std::size_t a = 0; a < p.n_owned(); ++a)
    for (std::size_t b = a + 1; b < p.n_owned(); ++b)
      EXPECT_GE(norm(p.pos[a] - p.pos[b]), p.radius[a] + p.radius[b] - 1e-12);
}

// dt = "auto" is safe from the start for the smallest fragment the run can make.
TEST(Grinding, AutoStepIsSafeForTheSmallestFragment) {
  Scene s = impacts(4, 0.05, 1.0, 1.0);
  s.breakage.minimum_radius = 0.02;
  const double dt = Simulation(s).dt();
  Scene small = impacts(4, 0.05, 1.0, 1.0);
  small.breakage.present = false;
  small.particles[0].radius = 0.02 / std::cbrt(6.0);
  EXPECT_DOUBLE_EQ(dt, Simulation(small).dt());
  EXPECT_LT(dt, Simulation(impacts(4, 0.05, 1.0, 1.0)).dt() * 0.9);
}

// Fragments at the size limit, run with the auto step: ore just above the smallest breakable
// radius strikes a floor at 8 m/s under gravity and breaks into fragments down to
// minimum_radius / 6^(1/3) (six each), which bounce off the floor and off each other in a box. The
// auto step chosen at the start (from that smallest fragment) keeps every later contact resolved:
// the overlap stays at its Hertz size, nothing leaves the box and the energy balance holds.
// With the step the parents alone would get, the same run overlaps more and books worse.
struct SizeLimitRun {
  double smallest = 0.0, max_overlap = 0.0, residual = 0.0, dissipated = 0.0, dt = 0.0;
  std::int64_t breakages = 0, particles = 0;
};

SizeLimitRun size_limit_run(bool fragments_known_to_dt) {
  const int n = 16;
  Scene s = impacts(n, 0.041, 8.0, 1.0e9);
  s.run.gravity = {0.0, -9.81};
  s.breakage.minimum_radius = 0.04;
  s.breakage.fragments_mean = 6.0;  // every break makes 6: all fragments at the size limit
  s.breakage.fragments_min = 6;
  const double width = 3.0 * 0.041 * n;
  for (double x : {-0.041, width}) s.walls.push_back(segment({x, 0.0}, {x, 2.0}, "ore"));
  if (!fragments_known_to_dt) {  // the parents' step, fixed
    Scene parents = s;
    parents.breakage.present = false;
    s.run.dt_auto = false;
    s.run.dt = Simulation(parents).dt();
  }
  Simulation sim(s);
  const double b0 = energy_balance(sim.diagnostics());
  SizeLimitRun out;
  out.dt = sim.dt();
  while (sim.time() < 0.3) {
    sim.step();
    out.max_overlap = std::max(out.max_overlap, sim.last_totals().max_overlap);
  }
  const ParticleStore& p = sim.particles();
  out.smallest = *std::min_element(p.radius.data(), p.radius.data() + p.n_owned());
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    EXPECT_GT(p.pos[k].y, 0.0) << "particle " << p.id[k] << " below the floor";
    EXPECT_GT(p.pos[k].x, -0.041) << "particle " << p.id[k] << " through the left wall";
    EXPECT_LT(p.pos[k].x, width) << "particle " << p.id[k] << " through the right wall";
  }
  const SeriesRow end = sim.diagnostics();
  out.residual = energy_balance(end) - b0;
  out.dissipated = end.dissipated_energy;
  out.breakages = end.breakages;
  out.particles = static_cast<std::int64_t>(p.n_owned());
  return out;
}

TEST(Grinding, FragmentsAtTheSizeLimitStayResolvedWithTheAutoStep) {
  const SizeLimitRun run = size_limit_run(true);
  const SizeLimitRun coarse = size_limit_run(false);
  std::printf(
      "[ size limit ] auto dt %.3e s: %lld breakages, %lld particles, smallest r %.4f m, "
      "max overlap %.4f r, residual %.2e of dissipated; parents' dt %.3e s: overlap "
      "%.4f r, residual %.2e\n",
      run.dt, static_cast<long long>(run.breakages), static_cast<long long>(run.particles),
      run.smallest, run.max_overlap, run.residual / run.dissipated, coarse.dt, coarse.max_overlap,
      coarse.residual / coarse.dissipated);
  EXPECT_EQ(run.breakages, 16);  // every parent broke; fragments are below minimum_radius
  EXPECT_EQ(run.particles, 6 * 16);
  EXPECT_NEAR(run.smallest, 0.041 / std::cbrt(6.0), 1e-12);
  EXPECT_LT(run.max_overlap, 0.02);
  EXPECT_LT(std::abs(run.residual), 3e-4 * run.dissipated);
  EXPECT_LT(run.dt, 0.85 * coarse.dt);
  // The bound tells the two steps apart: the parents' step books 8 times worse (6.6e-4).
  EXPECT_GT(std::abs(coarse.residual), 3e-4 * coarse.dissipated);
}

// A feed by mass rate at a given point: the mass fed keeps up with rate x t to within one
// particle, every particle is born at the point, and the feed waits while the point is taken.
TEST(Grinding, FeedByMassRateAtAPointKeepsUpAndWaitsForRoom) {
  Scene s = testing_support::thesis_drum_scene(60, 0.0, 16);
  s.materials.push_back(thesis_ore());
  s.feed.present = true;
  s.feed.material = "ore";
  s.feed.mass_rate = 200.0;  // kg/s: one 0.05 m ore particle (2.5 kg) every 12.6 ms
  s.feed.radius_min = s.feed.radius_max = 0.05;
  s.feed.has_point = true;
  s.feed.point = {0.0, 1.5};
  Simulation sim(s);
  const double m_particle = Disc::mass(0.05, 4800.0);
  std::int64_t seen = 0;
  while (sim.time() < 0.3) {
    sim.step();
    const GrindingTotals& g = sim.grinding()->totals();
    EXPECT_LE(g.fed_mass, 200.0 * sim.time() + m_particle + 1e-9);
    if (g.fed_count == seen) continue;
    seen = g.fed_count;
    const ParticleStore& p = sim.particles();
    const auto newest = std::max_element(p.id.data(), p.id.data() + p.n_owned()) - p.id.data();
    EXPECT_EQ(p.pos[static_cast<std::size_t>(newest)].x, 0.0);
    EXPECT_EQ(p.pos[static_cast<std::size_t>(newest)].y, 1.5);
  }
  // A particle at the point blocks the next until it has fallen clear (0.1 m from rest takes
  // 0.14 s), so the feed falls behind the rate while it waits.
  const GrindingTotals& g = sim.grinding()->totals();
  EXPECT_GE(g.fed_count, 3);
  EXPECT_LT(g.fed_mass, 200.0 * 0.3);  // it waited for room
}

// The force loop hands the grinding the pairs whose breakage test is due, instead of the
// grinding scanning every listed pair's history after the step. None may be missed: after
// every step (its tests run and marked) no listed pair of the committed state is still due,
// while many were tested on the way, and ore broke.
TEST(Grinding, TheForceLoopNamesEveryPairWhoseTestIsDue) {
  Simulation sim(testing_support::grinding_drum_scene());
  const std::size_t slot = sim.contacts().history_offset("peak_energy");
  std::size_t named = 0;
  while (sim.time() < 0.3) {
    sim.step();
    named += sim.contacts().breakage_tests_due().size();
    const PairList& pl = sim.pairs();
    std::size_t still_due = 0;
    for (std::size_t k = 0; k < pl.size(); ++k) {
      const double* h = pl.history_of(k) + slot;
      still_due += TrackBreakage::test_due(h[TrackBreakage::kPeak], h[TrackBreakage::kEnergy],
                                           h[TrackBreakage::kTested]);
    }
    ASSERT_EQ(still_due, 0u) << "at step " << sim.step_count();
  }
  EXPECT_GT(named, 100u);
  EXPECT_GT(sim.grinding()->totals().breakages, 0);
}

}  // namespace
}  // namespace dem2d

namespace dem2d {
namespace {

// Vogel and Peukert's law on equal impacts at three sizes: every sphere of a size meets the floor
// alike (one specific energy W, the same at every size for a given speed), and the fraction
// that breaks is 1 - exp(-f_mat d (W - xw_min / d)) within its binomial band: larger spheres
// break more often. Survivors carry the damage W - W_min (J/kg).
TEST(Grinding, VogelPeukertBreaksEachSizeAtItsProbability) {
  const int n = 400;
  double last = 0.0;
  for (const double r : {0.01, 0.02, 0.04}) {
    Scene s = impacts(n, r, 1.0, 1.0);
    s.breakage.model = BreakageModel::kVogelPeukert;
    s.breakage.f_mat = 20.0;
    s.breakage.xw_min = 0.001;
    Simulation sim(s);
    sim.run_until(0.004 * r / 0.05 + 0.002);
    const std::vector<BreakageRecord> breaks = sim.grinding()->take_breakages();
    const ParticleStore& ps = sim.particles();
    double damage = -1.0;
    int survivors = 0;
    for (std::size_t k = 0; k < ps.n_owned(); ++k) {
      if (ps.id[k] >= n) continue;
      ++survivors;
      if (damage < 0.0) damage = (*ps.damage())[k];
      EXPECT_NEAR((*ps.damage())[k], damage, 1e-9 * damage);
    }
    ASSERT_GT(damage, 0.0) << "r = " << r;
    for (const BreakageRecord& b : breaks)
      EXPECT_NEAR(b.specific_energy - 0.001 / (2.0 * r), damage, 1e-9 * damage);
    const double p = 1.0 - std::exp(-20.0 * 2.0 * r * damage);
    const double fraction = static_cast<double>(breaks.size()) / n;
    EXPECT_EQ(survivors + static_cast<int>(breaks.size()), n);
    EXPECT_NEAR(fraction, p, 4.0 * std::sqrt(p * (1.0 - p) / n))
        << "r = " << r << ", W - W_min = " << damage << " J/kg";
    EXPECT_GT(fraction, last);
    last = fraction;
  }
}

}  // namespace
}  // namespace dem2d

namespace dem2d {
namespace {

// An ore sphere bouncing between a floor and a ceiling of steel takes the share
// c_ore / (c_ore + c_steel) of each contact's peak strain energy, c = (1 - nu^2) / E: 10/13 for
// the thesis's ore and steel. With energy_split = "whole" (the thesis's reading) it takes all.
TEST(Grinding, AnOreSphereOnSteelTakesItsComplianceShareOfEachContact) {
  for (const EnergySplit split : {EnergySplit::kCompliance, EnergySplit::kWhole}) {
    Scene s = impacts(1, 0.05, 4.0, 1.0e-30);
    s.materials.push_back(testing_support::thesis_steel());
    s.walls.front().material = "steel";
    s.walls.push_back(segment({0.2, 0.3}, {-0.2, 0.3}, "steel"));
    s.breakage.energy_split = split;
    const double share = split == EnergySplit::kWhole ? 1.0 : 10.0 / 13.0;
    Simulation sim(s);
    const std::size_t slot = sim.contacts().history_offset("peak_energy");
    double expected = 0.0, peak = 0.0;
    int impacts_seen = 0;
    while (sim.time() < 0.4) {
      sim.step();
      const WallPairList& wl = sim.wall_pairs();
      double now = 0.0;
      for (std::size_t k = 0; k < wl.size(); ++k) now = std::max(now, wl.history_of(k)[slot]);
      if (now == 0.0 && peak > 0.0) {
        expected += share * peak - 0.1;
        ++impacts_seen;
        EXPECT_NEAR((*sim.particles().damage())[0], expected, 1e-9 * expected);
      }
      peak = now;
    }
    EXPECT_GE(impacts_seen, 4);
  }
}

// Two ore spheres meet head-on, and an ore sphere meets a steel ball: each contact is one loading
// event, tested once, each breakable body with its own share (1/2 against ore, 10/13 against
// steel); the steel takes no damage.
TEST(Grinding, APairContactIsOneLoadingEventWithEachBodysShare) {
  Scene s;
  s.deck_path = "test";
  s.materials = {thesis_ore(), testing_support::thesis_steel()};
  s.contact.rolling = RollingModelKind::kNone;
  s.run.gravity = {0.0, 0.0};
  s.particles.push_back(ball("ore", 0.05, {-0.06, 0.0}, {2.0, 0.0}));
  s.particles.push_back(ball("ore", 0.05, {0.06, 0.0}, {-2.0, 0.0}));
  s.particles.push_back(ball("ore", 0.05, {-0.06, 1.0}, {2.0, 0.0}));
  s.particles.push_back(ball("steel", 0.05, {0.06, 1.0}, {-2.0, 0.0}));
  s.breakage.present = true;
  s.breakage.material = "ore";
  s.breakage.strength = 1e-30;
  s.breakage.minimum_energy = 0.0;
  s.breakage.minimum_radius = 0.04;
  Simulation sim(s);
  const std::size_t slot = sim.contacts().history_offset("peak_energy");
  std::map<std::int64_t, double> peak;  // by the smaller id of the pair
  while (sim.time() < 0.01) {
    sim.step();
    const PairList& pl = sim.contacts().pairs();
    for (std::size_t k = 0; k < pl.size(); ++k) {
      const double e = pl.history[k * pl.width + slot];
      double& p = peak[std::min(pl.id_i[k], pl.id_j[k])];
      p = std::max(p, e);
    }
  }
  ASSERT_GT(peak[0], 0.0);
  ASSERT_GT(peak[2], 0.0);
  const ParticleStore& p = sim.particles();
  std::map<std::int64_t, double> damage;
  for (std::size_t k = 0; k < p.n_owned(); ++k) damage[p.id[k]] = (*p.damage())[k];
  EXPECT_NEAR(damage[0], 0.5 * peak[0], 1e-12 * peak[0]);
  EXPECT_NEAR(damage[1], 0.5 * peak[0], 1e-12 * peak[0]);
  EXPECT_NEAR(damage[2], 10.0 / 13.0 * peak[2], 1e-12 * peak[2]);
  EXPECT_EQ(damage[3], 0.0);
}

// t10 progeny in a run: 200 spheres break on the floor; at each break the fragments' masses and
// the fines add up to the parent's, the fragments carry the parent's momentum, the recorded t10
// lies in the band of the law A (1 - exp(-b E_cs)) that the quarter-octave classes allow, and
// the mass balance initial = in mill + discharged (the fines) holds to round-off.
TEST(Grinding, T10BreaksKeepMassAndMomentumAndFollowTheirLaw) {
  const int n = 200;
  Scene s = impacts(n, 0.05, 3.0, 1.0);
  BreakageSpec& b = s.breakage;
  b.model = BreakageModel::kVogelPeukert;
  b.f_mat = 1e3;
  b.xw_min = 0.0;
  b.fragments = FragmentLaw::kT10;
  b.t10_a = 60.0;
  b.t10_b = 300.0;  // t/kWh: a soft ore, so that these impacts give t10 of several per cent
  b.fines_diameter = 0.01;
  Simulation sim(s);
  const double m0 = sim.diagnostics().mill_mass;
  sim.run_until(0.006);
  const std::vector<BreakageRecord> breaks = sim.grinding()->take_breakages();
  const std::vector<FragmentRecord> fragments = sim.grinding()->take_fragments();
  ASSERT_GT(breaks.size(), n / 2u);
  std::map<std::int64_t, double> born;
  for (const FragmentRecord& f : fragments) born[f.parent] += f.mass;
  double fines = 0.0;
  for (const BreakageRecord& r : breaks) {
    EXPECT_NEAR(born[r.parent] + r.fines_mass, r.mass, 1e-13 * r.mass) << r.parent;
    fines += r.fines_mass;
    const double x = 2.0 * r.radius, e_cs = r.specific_energy / 3600.0;
    const double t10 = 0.6 * (1.0 - std::exp(-300.0 * e_cs));
    const double alpha = std::log(t10) / std::log(0.1);
    // The class edges X 2^(-k/4) around X / 10: the mass below X / 10 lies between the law at
    // the lower edge and the law at the upper edge plus one fragment of the class above it.
    const double lo = x * std::exp2(-0.25 * 14), hi = x * std::exp2(-0.25 * 13);
    const double one = Disc::mass(0.5 * hi * std::exp2(0.125), 4800.0);
    EXPECT_GE(r.t10 / 100.0 * r.mass, r.mass * std::pow(lo / x, alpha) * (1.0 - 1e-9));
    EXPECT_LE(r.t10 / 100.0 * r.mass, r.mass * std::pow(hi / x, alpha) + one);
  }
  EXPECT_GT(fines, 0.0);
  const SeriesRow row = sim.diagnostics();
  EXPECT_NEAR(row.mill_mass + row.discharged_mass, m0, 1e-12 * m0);
  EXPECT_NEAR(row.discharged_mass, fines, 1e-12 * m0);
  EXPECT_NEAR(sim.grinding()->totals().fines_mass, fines, 1e-12 * m0);
}

// The grate: ore narrower than the aperture (a diameter) with its centre in the ring within
// grate_width of the shell leaves; wider ore, ore inside the ring's inner edge and steel stay.
TEST(Grinding, TheGrateLetsOutOnlyNarrowOreInItsRing) {
  Scene s;
  s.deck_path = "test";
  s.materials = {thesis_ore(), testing_support::thesis_steel()};
  s.run.gravity = {0.0, 0.0};
  s.drum.present = true;
  s.drum.radius = 1.0;
  s.drum.material = "steel";
  const auto add = [&s](const char* material, double r, Vec2 x) {
    s.particles.push_back(ball(material, r, x));
  };
  add("ore", 0.02, {0.0, -0.85});    // 4 cm in the ring: leaves
  add("ore", 0.02, {0.85, 0.0});     // anywhere around the ring: leaves
  add("ore", 0.02, {0.0, -0.7});     // inside the ring's inner edge (0.8 m)
  add("ore", 0.04, {0.0, 0.85});     // 8 cm: wider than the aperture
  add("steel", 0.02, {-0.85, 0.0});  // not the sieve's material
  s.sieve = {.present = true,
             .material = "ore",
             .type = DischargeType::kGrate,
             .aperture = 0.05,
             .grate_width = 0.2};
  Simulation sim(s);
  const double m0 = sim.diagnostics().mill_mass;
  sim.step();
  std::vector<std::int64_t> out;
  for (const ProductRecord& r : sim.grinding()->take_product()) out.push_back(r.id);
  EXPECT_EQ(out, (std::vector<std::int64_t>{0, 1}));
  const SeriesRow r = sim.diagnostics();
  EXPECT_NEAR(r.mill_mass + r.discharged_mass, m0, 1e-14 * m0);
}

// The overflow: while the ore hold-up exceeds `holdup`, the finest ore narrower than the aperture
// leaves, smallest first, until the hold-up is at or below it; then nothing leaves.
TEST(Grinding, TheOverflowLetsOutTheFinestUntilTheHoldUpIsBack) {
  Scene s;
  s.deck_path = "test";
  s.materials = {thesis_ore()};
  s.run.gravity = {0.0, 0.0};
  const double radii[] = {0.03, 0.01, 0.02, 0.015, 0.05, 0.025};
  double total = 0.0;
  for (int k = 0; k < 6; ++k) {
    s.particles.push_back(ball("ore", radii[k], {0.2 * k, 0.0}));
    total += Disc::mass(radii[k], 4800.0);
  }
  // Above the hold-up by more than the two finest together, less than the three finest.
  const double m1 = Disc::mass(0.01, 4800.0), m2 = Disc::mass(0.015, 4800.0),
               m3 = Disc::mass(0.02, 4800.0);
  s.sieve = {.present = true,
             .material = "ore",
             .type = DischargeType::kOverflow,
             .aperture = 0.055,  // the 5 cm one is too wide
             .holdup = total - m1 - m2 - 0.5 * m3};
  Simulation sim(s);
  sim.step();
  std::vector<std::int64_t> out;
  for (const ProductRecord& r : sim.grinding()->take_product()) out.push_back(r.id);
  EXPECT_EQ(out, (std::vector<std::int64_t>{1, 2, 3}));
  EXPECT_LE(sim.diagnostics().ore_mass, s.sieve.holdup);
  sim.step();
  EXPECT_TRUE(sim.grinding()->take_product().empty());
}

}  // namespace
}  // namespace dem2d

namespace dem2d {
namespace {

// Fed ore is placed outside the discharge zone (with its largest radius to spare), where the
// charge is thinnest: a central box and a grate ring both; a zone that leaves no place is refused.
TEST(Grinding, TheFeedKeepsOutOfTheDischargeZone) {
  for (const DischargeType type : {DischargeType::kBox, DischargeType::kGrate}) {
    Scene s = testing_support::thesis_drum_scene(60, 1.5, 16);
    s.materials.push_back(thesis_ore());
    s.feed = {.present = true,
              .material = "ore",
              .period = 0.004,
              .radius_min = 0.05,
              .radius_max = 0.08};
    s.sieve = {.present = true,
               .material = "ore",
               .type = type,
               .box_min = {-1.0, -1.0},
               .box_max = {1.0, 1.0},
               .aperture = 0.5,  // every fed particle would pass
               .grate_width = 0.6};
    Simulation sim(s);
    std::int64_t seen = 0;
    const double inner = 2.5 * std::cos(std::numbers::pi / 16) - 0.6;
    while (sim.time() < 0.2) {
      sim.step();
      const ParticleStore& p = sim.particles();
      if (sim.grinding()->totals().fed_count == seen) continue;
      seen = sim.grinding()->totals().fed_count;
      const auto k = static_cast<std::size_t>(
          std::max_element(p.id.data(), p.id.data() + p.n_owned()) - p.id.data());
      const Vec2 x = p.pos[k];
      if (type == DischargeType::kBox)
        EXPECT_TRUE(std::abs(x.x) > 1.08 || std::abs(x.y) > 1.08) << x.x << ", " << x.y;
      else
        EXPECT_LE(norm(x) + 0.08, inner);
    }
    EXPECT_GE(seen, 40);
  }
  Scene s = testing_support::thesis_drum_scene(60, 1.5, 16);
  s.materials.push_back(thesis_ore());
  s.feed = {
      .present = true, .material = "ore", .period = 0.004, .radius_min = 0.05, .radius_max = 0.08};
  s.sieve = {.present = true, .material = "ore", .box_min = {-3.0, -3.0}, .box_max = {3.0, 3.0}};
  EXPECT_THROW(Simulation{s}, InputError);
}

}  // namespace
}  // namespace dem2d
