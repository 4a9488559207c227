// The ore's breakage laws as functions (core/mill/breakage_laws.hpp) and the size distributions
// (core/mill/size_classes.hpp): the t10 progeny keep the parent's mass exactly and follow the
// law within one fragment at every class edge, their places keep momentum and do not add
// energy, and the size classes add up exactly and read passing sizes between the sizes present.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/mill/breakage_laws.hpp"
#include "core/mill/size_classes.hpp"
#include "core/shape/disc.hpp"

namespace dem2d {
namespace {

TEST(BreakageLaws, ComplianceShareIsTheHertzApproachOfEachSurface) {
  // Thesis Table 1: ore E = 6e10, steel E = 2e11, both nu = 0.25.
  const double ore = compliance(6.0e10, 0.25), steel = compliance(2.0e11, 0.25);
  EXPECT_DOUBLE_EQ(energy_share(ore, ore), 0.5);
  EXPECT_NEAR(energy_share(ore, steel), (1.0 / 6.0) / (1.0 / 6.0 + 1.0 / 20.0), 1e-15);  // 10/13
  EXPECT_NEAR(energy_share(ore, steel) + energy_share(steel, ore), 1.0, 1e-15);
}

TEST(BreakageLaws, VogelPeukertProbabilityHasItsSizeEffectAndThreshold) {
  const double f = 0.5, xw = 0.05;
  for (const double d : {0.02, 0.05, 0.1}) {
    EXPECT_EQ(vogel_peukert_probability(f, xw, d, 0.99 * xw / d), 0.0);  // below the threshold
    const double w = 10.0;
    EXPECT_NEAR(vogel_peukert_probability(f, xw, d, w), 1.0 - std::exp(-f * d * (w - xw / d)),
                1e-15);
  }
  // k equal loadings survived one by one: 1 - exp(-f d k (w - w_min)), Vogel and Peukert's form.
  const double d = 0.05, w = 3.0, p1 = vogel_peukert_probability(f, xw, d, w);
  EXPECT_NEAR(1.0 - std::pow(1.0 - p1, 4), 1.0 - std::exp(-f * d * 4 * (w - xw / d)), 1e-14);
}

TEST(BreakageLaws, T10AndItsProgenyExponent) {
  EXPECT_NEAR(t10_fraction(60.0, 1.0, 0.5), 0.6 * (1.0 - std::exp(-0.5)), 1e-15);
  EXPECT_NEAR(std::pow(0.1, progeny_exponent(0.25)), 0.25, 1e-14);
  EXPECT_NEAR(progeny_exponent(0.1), 1.0, 1e-15);
  EXPECT_EQ(progeny_exponent(0.0), 1e3);  // nothing finer: all the mass at the parent's size
}

// Mass exact; at every class edge x of the progeny the mass placed below x exceeds the law's
// M (x / X)^alpha by less than one fragment of the class above x (what that class carried down).
TEST(BreakageLaws, T10ProgenyKeepTheMassAndFollowTheLawWithinOneFragment) {
  const double rho = 4800.0, radius = 0.05, big_x = 0.1, fines = 0.008;
  const double mass = Disc::mass(radius, rho);
  for (const double t10 : {1e-4, 0.003, 0.05, 0.2, 0.5, 0.8}) {
    const double alpha = progeny_exponent(t10);
    const Progeny g = t10_progeny(radius, rho, alpha, fines);
    double placed = g.fines_mass;
    for (const double r : g.radii) placed += Disc::mass(r, rho);
    EXPECT_NEAR(placed, mass, 1e-13 * mass) << "t10 = " << t10;
    EXPECT_GE(g.fines_mass, 0.0);
    EXPECT_LE(g.fines_law_mass, g.fines_mass * (1.0 + 1e-12));
    for (std::size_t k = 1; k < g.radii.size(); ++k) EXPECT_LE(g.radii[k], g.radii[k - 1]);
    for (int k = 1; big_x * std::exp2(-0.25 * k) > fines; ++k) {
      const double x = big_x * std::exp2(-0.25 * k);
      double below = g.fines_mass;
      for (const double r : g.radii)
        if (2.0 * r < x) below += Disc::mass(r, rho);
      const double one = Disc::mass(0.5 * x * std::exp2(0.125), rho);
      const double excess = below - mass * std::pow(x / big_x, alpha);
      EXPECT_GE(excess, -1e-12 * mass) << "t10 = " << t10 << ", edge " << x;
      EXPECT_LT(excess, one * (1.0 + 1e-9)) << "t10 = " << t10 << ", edge " << x;
    }
  }
  // t10 near 0: one big piece and chips, never the parent itself.
  const Progeny g = t10_progeny(radius, rho, progeny_exponent(1e-6), fines);
  ASSERT_GE(g.radii.size(), 1u);
  EXPECT_LT(g.radii[0], radius);
}

TEST(BreakageLaws, FragmentPlacesKeepTheMassCentreAndStayWithinTheParentsInertia) {
  std::mt19937_64 draw(5);
  std::uniform_real_distribution<double> u(0.05, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double parent = 0.05;
    std::vector<double> radii(1 + trial % 40);
    double volume = 0.0;
    for (double& r : radii) {
      r = parent * u(draw);
      volume += r * r * r;
    }
    // Fragments hold at most the parent's mass (the rest is fines).
    const double scale = std::cbrt(u(draw) * parent * parent * parent / volume);
    for (double& r : radii) r = std::min(0.95 * parent, scale * r);
    std::sort(radii.rbegin(), radii.rend());
    const std::vector<Offset> o = fragment_offsets(parent, radii, 0.3 * trial);
    double mx = 0.0, my = 0.0, m = 0.0, inertia = 0.0;
    for (std::size_t k = 0; k < radii.size(); ++k) {
      const double mk = std::pow(radii[k], 3);
      m += mk;
      mx += mk * o[k].x;
      my += mk * o[k].y;
      inertia += mk * (o[k].x * o[k].x + o[k].y * o[k].y) + 0.4 * mk * radii[k] * radii[k];
    }
    EXPECT_NEAR(mx / m, 0.0, 1e-15) << trial;
    EXPECT_NEAR(my / m, 0.0, 1e-15) << trial;
    EXPECT_LE(inertia, 0.4 * std::pow(parent, 5) * (1.0 + 1e-12)) << trial;
  }
}

TEST(SizeMasses, ClassesAddUpExactlyAndPassingSizesLieBetweenTheSizesPresent) {
  SizeMasses m;
  EXPECT_TRUE(std::isnan(m.passing_size(80.0)));
  // 100 particles of diameter 0.050-0.079 m: P80 below the largest, above the smallest.
  double total = 0.0;
  for (int k = 0; k < 100; ++k) {
    const double d = 0.05 + 0.0003 * k;
    m.add(d, Disc::mass(0.5 * d, 4800.0));
    total += Disc::mass(0.5 * d, 4800.0);
  }
  EXPECT_NEAR(m.total_kg(), total, 100 * SizeMasses::kUnit);
  const double p80 = m.passing_size(80.0);
  EXPECT_GT(p80, 0.05);
  EXPECT_LE(p80, 0.05 + 0.0003 * 99);
  EXPECT_NEAR(m.mass_below(1.0), m.total_kg(), 1e-12);
  EXPECT_EQ(m.mass_below(0.049), 0.0);
  // Classes: each diameter lies in [edge(k - 1), edge(k)).
  for (const double d : {1e-7, 1e-6, 3.3e-3, 0.0625, 0.1, 9.9, 20.0}) {
    const int k = SizeMasses::size_class(d);
    if (k > 0) {
      EXPECT_GE(d, SizeMasses::edge(k - 1)) << d;
    }
    EXPECT_LT(d, SizeMasses::edge(k)) << d;
  }
  // Fines spread by the law below their top: the classes hold exactly the fines' mass, and the
  // mass below x follows law_kg (x / top)^alpha to within a class's rounding.
  SizeMasses f;
  f.add_fines(2.0, 1.5, 0.01, 0.7);
  EXPECT_EQ(f.total_kg(), SizeMasses::units(2.0) * SizeMasses::kUnit);
  const double x = SizeMasses::edge(SizeMasses::size_class(0.001) - 1);
  EXPECT_NEAR(f.mass_below(x), 1.5 * std::pow(x / 0.01, 0.7), 1e-9);
}

}  // namespace
}  // namespace dem2d
