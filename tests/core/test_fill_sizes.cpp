// [[fill]] by bed filling, its laws of sizes (normal and lognormal by mass, a table of sizes and
// mass fractions) and mixed fills: the placed charge against what the deck asks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/mill/mill_analytics.hpp"
#include "core/setup/fill.hpp"
#include "core/setup/size_law.hpp"
#include "support/scenes.hpp"

namespace dem2d {
namespace {

Scene drum_scene(double radius) {
  Scene s;
  s.deck_path = "test.in";
  s.materials.push_back(testing_support::make_material("steel", 7800, 2e11, 0.25, 0.5, 0.2, 0.02));
  s.materials.push_back(testing_support::make_material("ore", 3000, 5e10, 0.25, 0.5, 0.4, 0.02));
  s.drum.present = true;
  s.drum.radius = radius;
  s.drum.material = "steel";
  return s;
}

FillSpec fill(const char* material, std::int64_t count, double r_min, double r_max,
              FillRegion region) {
  return testing_support::fill_spec(material, count, r_min, r_max, region);
}

// Places the scene's fills into `p` (empty) and checks no two overlap.
void place(const Scene& s, ParticleStore& p) {
  Walls walls(s);
  place_particles(s, walls, p);
  for (std::size_t a = 0; a < p.size(); ++a)  // no overlaps, inside the shell
    for (std::size_t b = a + 1; b < p.size(); ++b)
      ASSERT_GE(norm(p.pos[a] - p.pos[b]), p.radius[a] + p.radius[b]) << a << ", " << b;
}

double total_area(const ParticleStore& p) {
  double area = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) area += std::numbers::pi * p.radius[k] * p.radius[k];
  return area;
}

// bed_filling = J places cross-sections of J kBedPacking pi R^2; --check's J (mill_numbers) of
// the placed charge is J, over by less than one particle's share.
TEST(FillSizes, BedFillingPlacesTheAskedJWithinOneParticle) {
  for (const double j : {0.1, 0.3}) {
    Scene s = drum_scene(1.0);
    FillSpec f = fill("steel", 0, 0.01, 0.03, FillRegion::kBottom);
    f.bed_filling = j;
    s.fills.push_back(f);
    ParticleStore p;
    place(s, p);
    const double drum_area = std::numbers::pi;
    const MillNumbers m = mill_numbers(s, charge_sizes(p, Domain{}));
    EXPECT_GE(m.bed_filling, j);
    EXPECT_LT(m.bed_filling - j, std::numbers::pi * 0.03 * 0.03 / (kBedPacking * drum_area));
    EXPECT_EQ(static_cast<std::int64_t>(p.size()), fill_count(s, 0));
  }
}

// A fill_fraction of J kBedPacking and a bed_filling of J place the same particles.
TEST(FillSizes, BedFillingIsTheFillFractionOverThePacking) {
  Scene a = drum_scene(1.0), b = drum_scene(1.0);
  FillSpec f = fill("steel", 0, 0.01, 0.03, FillRegion::kBottom);
  f.bed_filling = 0.25;
  a.fills.push_back(f);
  f.bed_filling = 0.0;
  f.fill_fraction = 0.25 * kBedPacking;
  b.fills.push_back(f);
  EXPECT_EQ(fill_target_area(a, a.fills[0]), 0.25 * kBedPacking * std::numbers::pi);
  EXPECT_NEAR(fill_target_area(b, b.fills[0]), fill_target_area(a, a.fills[0]), 1e-15);
  EXPECT_EQ(fill_radii(a, 0).size(), fill_radii(b, 0).size());
}

// The share of the placed mass (d^3) in each class [edges[i], edges[i+1]) of diameters, and
// its standard error (delta method for a ratio of sums).
struct MassShares {
  std::vector<double> share, se;
};
MassShares mass_shares(const ParticleStore& p, const std::vector<double>& edges) {
  const std::size_t n = p.size(), classes = edges.size() - 1;
  MassShares out{std::vector<double>(classes, 0.0), std::vector<double>(classes, 0.0)};
  double total = 0.0;
  for (std::size_t k = 0; k < n; ++k) total += std::pow(2.0 * p.radius[k], 3);
  for (std::size_t c = 0; c < classes; ++c) {
    for (std::size_t k = 0; k < n; ++k) {
      const double d = 2.0 * p.radius[k];
      if (d >= edges[c] && (d < edges[c + 1] || c + 1 == classes))
        out.share[c] += d * d * d / total;
    }
    double var = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double d = 2.0 * p.radius[k];
      const double in = (d >= edges[c] && (d < edges[c + 1] || c + 1 == classes)) ? 1.0 : 0.0;
      const double term = d * d * d * (in - out.share[c]) / (total / static_cast<double>(n));
      var += term * term;
    }
    out.se[c] = std::sqrt(var) / static_cast<double>(n);
  }
  return out;
}

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// Checks each class's placed mass share against the law's (cdf of the diameter by mass,
// truncated): within 4 standard errors, and that sampling by number would have missed.
void expect_mass_shares(const ParticleStore& p, const std::vector<double>& edges,
                        double (*cdf)(double)) {
  const MassShares got = mass_shares(p, edges);
  const double all = cdf(edges.back()) - cdf(edges.front());
  double worst_by_number = 0.0;
  for (std::size_t c = 0; c + 1 < edges.size(); ++c) {
    const double want = (cdf(edges[c + 1]) - cdf(edges[c])) / all;
    EXPECT_LT(std::abs(got.share[c] - want), 4.0 * got.se[c])
        << "class " << c << ": " << got.share[c] << " vs " << want << " (se " << got.se[c] << ")";
    EXPECT_GT(got.se[c], 0.0);
    double number = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) {
      const double d = 2.0 * p.radius[k];
      number += (d >= edges[c] && d < edges[c + 1]) ? 1.0 / static_cast<double>(p.size()) : 0.0;
    }
    worst_by_number = std::max(worst_by_number, std::abs(number - want) / got.se[c]);
  }
  EXPECT_GT(worst_by_number, 8.0);  // the number shares are far from the mass shares
}

TEST(FillSizes, NormalByMassMeetsItsMassFractions) {
  Scene s = drum_scene(2.5);
  FillSpec f = fill("ore", 4000, 0.01, 0.03, FillRegion::kFull);
  f.size_distribution = SizeDistribution::kNormal;
  f.d50 = 0.04;
  f.sigma = 0.01;
  s.fills.push_back(f);
  ParticleStore p;
  place(s, p);
  ASSERT_EQ(p.size(), 4000u);
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_GE(p.radius[k], 0.01);
    EXPECT_LE(p.radius[k], 0.03);
  }
  expect_mass_shares(p, {0.02, 0.03, 0.035, 0.04, 0.045, 0.05, 0.06},
                     [](double d) { return normal_cdf((d - 0.04) / 0.01); });
}

TEST(FillSizes, LognormalByMassMeetsItsMassFractions) {
  Scene s = drum_scene(2.5);
  FillSpec f = fill("ore", 4000, 0.0075, 0.03, FillRegion::kFull);
  f.size_distribution = SizeDistribution::kLognormal;
  f.d50 = 0.03;
  f.geometric_sd = 1.5;
  s.fills.push_back(f);
  ParticleStore p;
  place(s, p);
  ASSERT_EQ(p.size(), 4000u);
  expect_mass_shares(p, {0.015, 0.02, 0.025, 0.03, 0.036, 0.045, 0.06},
                     [](double d) { return normal_cdf(std::log(d / 0.03) / std::log(1.5)); });
}

// Without truncation to speak of, a lognormal law by mass is lognormal by number with the same
// geometric sd and the median d50 exp(-3 ln^2 sg) (Hatch-Choate).
TEST(FillSizes, LognormalNumberMedianIsHatchChoate) {
  FillSpec f = fill("ore", 1, 0.0015, 0.15, FillRegion::kFull);
  f.size_distribution = SizeDistribution::kLognormal;
  f.d50 = 0.03;
  f.geometric_sd = 1.3;
  const DiameterLaw law(f);
  const double ln = std::log(1.3);
  EXPECT_NEAR(law.diameter(0.5), 0.03 * std::exp(-3.0 * ln * ln), 1e-4);
  EXPECT_NEAR(law.diameter(normal_cdf(1.0)), 0.03 * std::exp(-3.0 * ln * ln) * 1.3, 2e-4);
}

// Counts per size within one particle of their exact share N (w_i / d_i^3) / sum_j (w_j / d_j^3),
// so each mass fraction is met to within a particle or two of the largest size.
void expect_table(const ParticleStore& p, const std::vector<double>& sizes,
                  const std::vector<double>& w) {
  double sum = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < sizes.size(); ++i) sum += w[i] / std::pow(sizes[i], 3);
  for (std::size_t k = 0; k < p.size(); ++k) mass += std::pow(2.0 * p.radius[k], 3);
  const double n = static_cast<double>(p.size());
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    double count = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) count += 2.0 * p.radius[k] == sizes[i];
    EXPECT_LT(std::abs(count - n * w[i] / std::pow(sizes[i], 3) / sum), 1.0) << "size " << i;
    EXPECT_LE(std::abs(count * std::pow(sizes[i], 3) / mass - w[i]),
              2.0 * std::pow(sizes.back(), 3) / mass)
        << "size " << i;
  }
}

TEST(FillSizes, TableMeetsItsMassFractionsWithinOneParticlePerSize) {
  Scene s = drum_scene(1.5);
  FillSpec f = fill("ore", 700, 0.0, 0.0, FillRegion::kBottom);
  f.size_distribution = SizeDistribution::kTable;
  f.sizes = {0.02, 0.035, 0.05};
  f.mass_fractions = {0.2, 0.3, 0.5};
  f.radius_min = 0.01;
  f.radius_max = 0.025;
  s.fills.push_back(f);
  ParticleStore p;
  place(s, p);
  ASSERT_EQ(p.size(), 700u);
  expect_table(p, f.sizes, f.mass_fractions);
  // Shuffled: the largest size is not all at the bottom (its mean height near the fill's).
  double y_all = 0.0, y_big = 0.0, big = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    y_all += p.pos[k].y / 700.0;
    if (p.radius[k] == 0.025) y_big += p.pos[k].y, big += 1.0;
  }
  EXPECT_NEAR(y_big / big, y_all, 0.08);
  // By bed filling: ceil(target / mean area) particles, apportioned the same way.
  s.fills[0].count = 0;
  s.fills[0].bed_filling = 0.2;
  ParticleStore q;
  place(s, q);
  const double target = 0.2 * kBedPacking * std::numbers::pi * 1.5 * 1.5;
  EXPECT_NEAR(total_area(q), target, std::numbers::pi * 0.025 * 0.025 * 2.0);
  expect_table(q, f.sizes, f.mass_fractions);
}

// Two bottom fills: stacked one over the other, or with mix = true one bed of both.
TEST(FillSizes, MixedBottomFillsShareOneBedStackedOnesDoNot) {
  for (const bool mix : {false, true}) {
    Scene s = drum_scene(1.0);
    s.fills.push_back(fill("steel", 150, 0.03, 0.03, FillRegion::kBottom));
    s.fills.push_back(fill("ore", 300, 0.01, 0.02, FillRegion::kBottom));
    s.fills[1].mix = mix;
    s.fills[1].index = 1;
    ParticleStore p;
    place(s, p);
    ASSERT_EQ(p.size(), 450u);
    double y[2] = {0.0, 0.0}, y2[2] = {0.0, 0.0};
    const double n[2] = {150.0, 300.0};
    for (std::size_t k = 0; k < p.size(); ++k) {
      const int m = k < 150 ? 0 : 1;  // ids in fill order
      EXPECT_EQ(p.material[k], m);
      y[m] += p.pos[k].y / n[m];
      y2[m] += p.pos[k].y * p.pos[k].y / n[m];
    }
    const double se = std::sqrt((y2[0] - y[0] * y[0]) / n[0] + (y2[1] - y[1] * y[1]) / n[1]);
    if (mix) {
      EXPECT_LT(std::abs(y[1] - y[0]), 3.0 * se) << y[0] << " " << y[1] << " se " << se;
    } else {
      EXPECT_GT(y[1] - y[0], 0.2) << y[0] << " " << y[1];  // the ore lies on the balls
    }
  }
}

}  // namespace
}  // namespace dem2d
