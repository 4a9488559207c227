// The angular-sector partition (src/parallel/sector_partition.hpp): sector_of, the distance to
// a wedge, and the three partitioners (validity, exact optimum, balance on a charge, determinism).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <vector>

#include "parallel/sector_partition.hpp"

namespace dem2d {
namespace {

constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------- sector_of

TEST(SectorOf, AxesAreSectorEdges) {
  const Vec2 c{0.0, 0.0};
  EXPECT_EQ(sector_of({1.0, 0.0}, c, 4), 0);
  EXPECT_EQ(sector_of({0.0, 1.0}, c, 4), 1);    // angle pi/2: the first angle of sector 1
  EXPECT_EQ(sector_of({-1.0, 0.0}, c, 4), 2);   // angle pi
  EXPECT_EQ(sector_of({0.0, -1.0}, c, 4), 3);   // angle 3 pi/2
  EXPECT_EQ(sector_of({1.0, 1.0}, c, 8), 1);    // angle pi/4 with 8 sectors
  EXPECT_EQ(sector_of({-1.0, -1.0}, c, 8), 5);  // angle 5 pi/4
  EXPECT_EQ(sector_of({1.0, -0.0}, c, 4), 0);   // atan2(-0, 1) = -0: sector 0
}

TEST(SectorOf, JustEitherSideOfAnEdge) {
  const Vec2 c{0.0, 0.0};
  const double eps = 1e-9;
  EXPECT_EQ(sector_of({std::cos(kPi / 2 - eps), std::sin(kPi / 2 - eps)}, c, 4), 0);
  EXPECT_EQ(sector_of({std::cos(kPi / 2 + eps), std::sin(kPi / 2 + eps)}, c, 4), 1);
  EXPECT_EQ(sector_of({1.0, eps}, c, 4), 0);
  EXPECT_EQ(sector_of({1.0, -eps}, c, 4), 3);
  // angle -1e-300 + 2 pi rounds to 2 pi: clamped into the last sector, not sector n.
  EXPECT_EQ(sector_of({1.0, -1e-300}, c, 4), 3);
  EXPECT_EQ(sector_of({1.0, -1e-300}, c, 1000), 999);
}

TEST(SectorOf, CentreAndOffsetCentre) {
  EXPECT_EQ(sector_of({0.0, 0.0}, {0.0, 0.0}, 16), 0);
  EXPECT_EQ(sector_of({2.0, 3.0}, {2.0, 3.0}, 16), 0);
  const Vec2 c{2.0, 3.0};
  EXPECT_EQ(sector_of({2.0, 4.0}, c, 4), 1);
  EXPECT_EQ(sector_of({1.0, 3.0}, c, 4), 2);
  EXPECT_EQ(sector_of({2.0, 2.0}, c, 4), 3);
  EXPECT_EQ(sector_of({5.0, 7.0}, c, 1), 0);
}

TEST(SectorOf, AgreesWithAngleEverywhere) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int k = 0; k < 20000; ++k) {
    const Vec2 x{u(rng), u(rng)};
    const int n = 1 + k % 97;
    double a = std::atan2(x.y, x.x);
    if (a < 0) a += 2 * kPi;
    const int s = sector_of(x, {0.0, 0.0}, n);
    ASSERT_GE(s, 0);
    ASSERT_LT(s, n);
    EXPECT_LE(s * (2 * kPi / n), a * (1 + 1e-15));
    EXPECT_GT((s + 1) * (2 * kPi / n), a * (1 - 1e-15));
  }
}

// ------------------------------------------------------------------------ distance_to_wedge

TEST(DistanceToWedge, QuarterWedgeExactValues) {
  const Vec2 c{0.0, 0.0};
  const double a = 0.0, b = kPi / 2;  // the first quadrant
  EXPECT_EQ(distance_to_wedge({1.0, 1.0}, c, a, b), 0.0);
  EXPECT_EQ(distance_to_wedge({0.0, 0.0}, c, a, b), 0.0);
  EXPECT_EQ(distance_to_wedge({2.0, 0.0}, c, a, b), 0.0);            // on the begin ray
  EXPECT_NEAR(distance_to_wedge({3.0, -2.0}, c, a, b), 2.0, 1e-15);  // below the x ray
  EXPECT_NEAR(distance_to_wedge({-2.0, 3.0}, c, a, b), 2.0, 1e-15);  // left of the y ray
  EXPECT_NEAR(distance_to_wedge({-1.0, -1.0}, c, a, b), std::sqrt(2.0), 1e-15);  // behind
  EXPECT_NEAR(distance_to_wedge({-3.0, -0.5}, c, a, b), std::hypot(3.0, 0.5), 1e-15);
  EXPECT_NEAR(distance_to_wedge({-0.001, 0.5}, c, a, b), 0.001, 1e-15);  // near the centre
  // The same wedge about another centre.
  EXPECT_NEAR(distance_to_wedge({13.0, 8.0}, {10.0, 10.0}, a, b), 2.0, 1e-14);
}

TEST(DistanceToWedge, WiderThanPi) {
  const Vec2 c{0.0, 0.0};
  // From pi/2 counter-clockwise to 2 pi: everything but the open first quadrant.
  EXPECT_EQ(distance_to_wedge({-1.0, -1.0}, c, kPi / 2, 2 * kPi), 0.0);
  EXPECT_EQ(distance_to_wedge({1.0, -5.0}, c, kPi / 2, 2 * kPi), 0.0);
  EXPECT_NEAR(distance_to_wedge({1.0, 2.0}, c, kPi / 2, 2 * kPi), 1.0, 1e-15);
  EXPECT_NEAR(distance_to_wedge({2.0, 1.0}, c, kPi / 2, 2 * kPi), 1.0, 1e-15);
  EXPECT_NEAR(distance_to_wedge({0.3, 0.2}, c, kPi / 2, 2 * kPi), 0.2, 1e-15);
  // From pi/4 to 2 pi (span 7 pi/4): the missing wedge is [0, pi/4).
  EXPECT_NEAR(distance_to_wedge({2.0, 0.5}, c, kPi / 4, 2 * kPi), 0.5, 1e-15);
  EXPECT_NEAR(distance_to_wedge({1.0, 0.9}, c, kPi / 4, 2 * kPi), 0.1 / std::sqrt(2.0), 1e-15);
  // Wrapping through angle 0: from 7 pi/4 to 2 pi + pi/4.
  EXPECT_EQ(distance_to_wedge({1.0, 0.0}, c, 7 * kPi / 4, 2 * kPi + kPi / 4), 0.0);
  EXPECT_NEAR(distance_to_wedge({-1.0, 0.0}, c, 7 * kPi / 4, 2 * kPi + kPi / 4), 1.0, 1e-15);
  EXPECT_NEAR(distance_to_wedge({0.0, 1.0}, c, 7 * kPi / 4, 2 * kPi + kPi / 4), std::sqrt(0.5),
              1e-15);
}

TEST(DistanceToWedge, FullWedgeIsEverything) {
  for (const Vec2 x : {Vec2{1.0, 2.0}, Vec2{-3.0, -0.1}, Vec2{0.0, 0.0}, Vec2{1.0, -1e-300}}) {
    EXPECT_EQ(distance_to_wedge(x, {0.0, 0.0}, 0.0, 2 * kPi), 0.0);
    EXPECT_EQ(distance_to_wedge(x, {0.0, 0.0}, 1.0, 1.0 + 2 * kPi), 0.0);
    EXPECT_EQ(distance_to_wedge(x, {0.0, 0.0}, 1.0, 1.0), 0.0);  // end = begin mod 2 pi
  }
  const SectorPartition one = partition_equal_angle(16, 1);
  EXPECT_EQ(distance_to_part({5.0, -1e-300}, {0.0, 0.0}, one, 0), 0.0);
}

// Distance by brute force: inside by cross products, outside the minimum over dense samples of
// the two bounding rays (sampling error <= half the step).
double brute_distance(Vec2 p, double a, double span) {
  const Vec2 ub{std::cos(a), std::sin(a)}, ue{std::cos(a + span), std::sin(a + span)};
  bool inside;
  if (span <= kPi)
    inside = cross(ub, p) >= 0 && cross(p, ue) >= 0;
  else
    inside = !(cross(ue, p) > 0 && cross(p, ub) > 0);
  if (inside) return 0.0;
  const int samples = 20000;
  const double reach = norm(p) + 1.0, step = reach / samples;
  double best = std::numeric_limits<double>::infinity();
  for (const Vec2 u : {ub, ue})
    for (int k = 0; k <= samples; ++k) best = std::min(best, norm(p - (k * step) * u));
  return best;
}

TEST(DistanceToWedge, MatchesBruteForce) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(-2 * kPi, 4 * kPi), span(0.05, 2 * kPi - 0.05),
      coord(-2.0, 2.0), small(-0.05, 0.05);
  const Vec2 c{0.7, -0.3};
  int outside = 0, wide = 0;
  for (int k = 0; k < 400; ++k) {
    const double a = angle(rng), s = span(rng);
    const Vec2 p = (k % 4 == 0) ? Vec2{small(rng), small(rng)} : Vec2{coord(rng), coord(rng)};
    const double d = distance_to_wedge(c + p, c, a, a + s);
    const double brute = brute_distance(p, a, s);
    const double step = (norm(p) + 1.0) / 20000;
    if (brute == 0.0) {
      EXPECT_LE(d, 1e-12) << "k " << k;
    } else {
      ++outside;
      if (s > kPi) ++wide;
      EXPECT_LE(d, brute + 1e-12) << "k " << k;
      EXPECT_GE(d, brute - 0.5 * step - 1e-12) << "k " << k;
    }
  }
  EXPECT_GT(outside, 100);
  EXPECT_GT(wide, 20);
}

TEST(DistanceToWedge, PartWedgesUseArcAngles) {
  const SectorPartition p = partition_equal_angle(8, 4);  // quarters
  ASSERT_EQ(p.arcs[1].first, 2);
  EXPECT_DOUBLE_EQ(arc_begin_angle(p, 1), kPi / 2);
  EXPECT_DOUBLE_EQ(arc_end_angle(p, 1), kPi);
  EXPECT_EQ(distance_to_part({-1.0, 1.0}, {0.0, 0.0}, p, 1), 0.0);
  EXPECT_NEAR(distance_to_part({1.0, 3.0}, {0.0, 0.0}, p, 1), 1.0, 1e-15);
  // A wrapping arc: sectors 7, 0 of 8 (angles 7 pi/4 .. 2 pi + pi/4). The only partition with
  // every part weighing 8 is {7, 0}, {1, 2}, {3, 4}, {5, 6}.
  const SectorPartition w = partition_ring_exact(std::vector<double>{5, 4, 4, 4, 4, 4, 4, 3}, 4);
  ASSERT_TRUE(is_valid(w));
  ASSERT_EQ(w.arcs[3].first, 7);
  ASSERT_EQ(w.arcs[3].count, 2);
  EXPECT_DOUBLE_EQ(arc_end_angle(w, 3) - arc_begin_angle(w, 3), kPi / 2);
  EXPECT_EQ(distance_to_part({1.0, 0.0}, {0.0, 0.0}, w, 3), 0.0);
  EXPECT_NEAR(distance_to_part({-1.0, 0.0}, {0.0, 0.0}, w, 3), 1.0, 1e-15);
}

// ------------------------------------------------------------------------------- partitions

// Independent check: every part one non-empty arc, all sectors covered once, canonical order.
void expect_contiguous(const SectorPartition& p, int n, int nparts) {
  ASSERT_EQ(p.n_sectors, n);
  ASSERT_EQ(p.owner.size(), static_cast<std::size_t>(n));
  ASSERT_EQ(p.parts(), nparts);
  std::vector<int> count(static_cast<std::size_t>(nparts), 0), runs(count);
  for (int s = 0; s < n; ++s) {
    const int q = p.owner[static_cast<std::size_t>(s)];
    ASSERT_GE(q, 0);
    ASSERT_LT(q, nparts);
    ++count[static_cast<std::size_t>(q)];
    if (nparts > 1 && q != p.owner[static_cast<std::size_t>((s + n - 1) % n)])
      ++runs[static_cast<std::size_t>(q)];
  }
  for (int q = 0; q < nparts; ++q) {
    const auto k = static_cast<std::size_t>(q);
    EXPECT_GE(count[k], 1) << "part " << q << " empty";
    EXPECT_EQ(count[k], p.arcs[k].count);
    if (nparts > 1) {
      EXPECT_EQ(runs[k], 1) << "part " << q << " not one arc";
    }
    EXPECT_EQ(p.owner[static_cast<std::size_t>(p.arcs[k].first)], q);
    if (q > 0) {
      EXPECT_GT(p.arcs[k].first, p.arcs[k - 1].first);
    }
  }
  EXPECT_TRUE(is_valid(p));
}

double max_part_work(const std::vector<double>& w, const SectorPartition& p) {
  const std::vector<double> pw = part_work(w, p);
  return *std::max_element(pw.begin(), pw.end());
}

// Optimum over every choice of nparts cut positions (the arcs start at the cuts).
double brute_force_bottleneck(const std::vector<double>& w, int nparts) {
  const int n = static_cast<int>(w.size());
  double best = std::numeric_limits<double>::infinity();
  for (unsigned mask = 0; mask < (1u << n); ++mask) {
    if (std::popcount(mask) != nparts) continue;
    std::vector<int> cuts;
    for (int s = 0; s < n; ++s)
      if (mask & (1u << s)) cuts.push_back(s);
    double worst = 0.0;
    for (std::size_t k = 0; k < cuts.size(); ++k) {
      const int b = cuts[k], e = (k + 1 < cuts.size()) ? cuts[k + 1] : cuts[0] + n;
      double sum = 0.0;
      for (int s = b; s < e; ++s) sum += w[static_cast<std::size_t>(s % n)];
      worst = std::max(worst, sum);
    }
    best = std::min(best, worst);
  }
  return best;
}

TEST(Partition, EqualAngleArcs) {
  const SectorPartition p = partition_equal_angle(10, 3);
  expect_contiguous(p, 10, 3);
  EXPECT_EQ(p.arcs[0].first, 0);
  EXPECT_EQ(p.arcs[0].count, 3);
  EXPECT_EQ(p.arcs[1].first, 3);
  EXPECT_EQ(p.arcs[1].count, 3);
  EXPECT_EQ(p.arcs[2].first, 6);
  EXPECT_EQ(p.arcs[2].count, 4);
  EXPECT_EQ(p.method, "equal-angle");
  EXPECT_THROW(partition_equal_angle(4, 5), std::invalid_argument);
  EXPECT_THROW(partition_equal_angle(4, 0), std::invalid_argument);
}

TEST(Partition, EveryMethodContiguousOnRandomWeights) {
  std::mt19937_64 rng(3);
  for (int n = 1; n <= 40; ++n) {
    for (int nparts = 1; nparts <= n; nparts += (n > 12 ? 3 : 1)) {
      std::vector<double> w(static_cast<std::size_t>(n)), b(w.size());
      for (std::size_t s = 0; s < w.size(); ++s) {
        // Zeros (empty sectors) and a few heavy ones.
        const auto r = rng() % 10;
        w[s] = r < 3 ? 0.0 : (r == 9 ? 50.0 : static_cast<double>(rng() % 7));
        b[s] = static_cast<double>(rng() % 5);
      }
      SCOPED_TRACE("n " + std::to_string(n) + " nparts " + std::to_string(nparts));
      expect_contiguous(partition_equal_angle(n, nparts), n, nparts);
      expect_contiguous(partition_ring_exact(w, nparts), n, nparts);
      const SectorPartition m = partition_metis(w, b, nparts);
      expect_contiguous(m, n, nparts);
      // Never worse than the accepted tolerance or the optimum.
      const double mean = std::accumulate(w.begin(), w.end(), 0.0) / nparts;
      EXPECT_LE(
          max_part_work(w, m),
          std::max(1.03 * mean, max_part_work(w, partition_ring_exact(w, nparts))) * (1 + 1e-12));
    }
  }
  // Mild weights, >= 4 sectors per part: METIS's own partitions are exercised and kept.
  int kept = 0, calls = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int nparts = 2 + static_cast<int>(rng() % 15);
    const int n = nparts * (4 + static_cast<int>(rng() % 20));
    std::vector<double> w(static_cast<std::size_t>(n)), b(w.size());
    for (std::size_t s = 0; s < w.size(); ++s) {
      w[s] = 1.0 + static_cast<double>(rng() % 10);
      b[s] = static_cast<double>(rng() % 5);
    }
    const SectorPartition m = partition_metis(w, b, nparts);
    expect_contiguous(m, n, nparts);
    const double opt = max_part_work(w, partition_ring_exact(w, nparts));
    const double mean = std::accumulate(w.begin(), w.end(), 0.0) / nparts;
    EXPECT_LE(max_part_work(w, m), std::max(1.03 * mean, opt) * (1 + 1e-12));
    EXPECT_GE(max_part_work(w, m), opt);
    if (m.method.starts_with("metis")) ++kept;
    ++calls;
  }
  EXPECT_GT(kept, calls / 4);
  // All-zero work is still split into non-empty arcs.
  const std::vector<double> zero(20, 0.0);
  expect_contiguous(partition_ring_exact(zero, 7), 20, 7);
  expect_contiguous(partition_metis(zero, zero, 7), 20, 7);
  EXPECT_EQ(imbalance(zero, partition_metis(zero, zero, 7)), 1.0);
}

TEST(Partition, ExactRingMatchesBruteForce) {
  std::mt19937_64 rng(5);
  int cases = 0, wrapping = 0;
  for (int n = 1; n <= 12; ++n) {
    for (int nparts = 1; nparts <= std::min(4, n); ++nparts) {
      for (int trial = 0; trial < 25; ++trial) {
        std::vector<double> w(static_cast<std::size_t>(n));
        for (double& v : w) v = static_cast<double>(rng() % 4 == 0 ? 0 : rng() % 21);
        const SectorPartition p = partition_ring_exact(w, nparts);
        expect_contiguous(p, n, nparts);
        // Integer weights: every sum is exact, so the optimum must be matched exactly.
        EXPECT_EQ(max_part_work(w, p), brute_force_bottleneck(w, nparts))
            << "n " << n << " nparts " << nparts << " trial " << trial;
        if (p.arcs.back().first + p.arcs.back().count > n) ++wrapping;
        ++cases;
      }
    }
  }
  EXPECT_GT(wrapping, 50);  // the optimum often needs an arc through sector 0
  EXPECT_EQ(cases, 25 * (1 + 2 + 3 + 9 * 4));
}

TEST(Partition, ExactRingRealWeightsAndKnownCase) {
  // 9 sectors, weights 1..9, 3 parts: total 45; {7,8}, {9,1,2,3}, {4,5,6} all weigh 15.
  const std::vector<double> w{1, 2, 3, 4, 5, 6, 7, 8, 9};
  EXPECT_EQ(max_part_work(w, partition_ring_exact(w, 3)), brute_force_bottleneck(w, 3));
  EXPECT_EQ(brute_force_bottleneck(w, 3), 15.0);
  const SectorPartition p = partition_ring_exact(w, 3);
  EXPECT_EQ(part_work(w, p), (std::vector<double>{15, 15, 15}));
  EXPECT_EQ(p.arcs[2].first, 8);  // {9, 1, 2, 3} wraps through sector 0
  EXPECT_EQ(p.arcs[2].count, 4);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<double> r(10);
    for (double& v : r) v = u(rng);
    const double opt = brute_force_bottleneck(r, 1 + trial % 4);
    EXPECT_NEAR(max_part_work(r, partition_ring_exact(r, 1 + trial % 4)), opt, 1e-12 * opt);
  }
}

// Particles per sector of a bed filling the circular segment below the chord at distance
// R cos(pi/3) from the centre (a third of the ring, centred on the bottom, angle 3 pi/2): the
// area of the segment inside each sector, (R^2 phi - d^2 tan phi) / 2 between the sector's
// angles phi measured from the bottom. Nothing elsewhere.
std::vector<double> charge_profile(int n) {
  const double half = kPi / 3, d = std::cos(half);
  auto area = [&](double phi) { return 0.5 * (phi - d * d * std::tan(phi)); };
  std::vector<double> w(static_cast<std::size_t>(n));
  for (int s = 0; s < n; ++s) {
    auto clip = [&](double a) { return std::clamp(a - 1.5 * kPi, -half, half); };
    w[static_cast<std::size_t>(s)] =
        1e4 * (area(clip((s + 1) * 2 * kPi / n)) - area(clip(s * 2 * kPi / n)));
  }
  return w;
}

// Boundary weights for the profile: the mean of the two neighbouring sectors.
std::vector<double> boundaries_of(const std::vector<double>& w) {
  std::vector<double> b(w.size());
  for (std::size_t s = 0; s < w.size(); ++s) b[s] = 0.5 * (w[s] + w[(s + 1) % w.size()]);
  return b;
}

TEST(Partition, MetisBalancesTheCharge) {
  for (const int nparts : {2, 4, 8}) {
    for (const int per_part : {16, 32}) {
      const int n = per_part * nparts;
      const std::vector<double> w = charge_profile(n);
      SCOPED_TRACE("nparts " + std::to_string(nparts) + ", " + std::to_string(per_part) +
                   " sectors per part");
      const SectorPartition m = partition_metis(w, boundaries_of(w), nparts);
      expect_contiguous(m, n, nparts);
      const double opt = imbalance(w, partition_ring_exact(w, nparts));
      const double got = imbalance(w, m);
      // Within 5 %, or, where the sector size makes 5 % impossible, the exact optimum.
      EXPECT_LE(got, std::max(1.05, opt) * (1 + 1e-12)) << m.method;
      if (per_part == 32) {
        EXPECT_LE(got, 1.05) << m.method;
      }
      const double equal = imbalance(w, partition_equal_angle(n, nparts));
      if (nparts >= 4) {
        EXPECT_GT(equal, 1.5);
      }
      EXPECT_GT(equal, got + 0.4);
    }
  }
  // Sector granularity: with 16 sectors per part the bed (43 of 128 sectors at 8 parts, about
  // 5 per part) cannot be cut within 5 %: the exact optimum is 1.0584 (4 parts), 1.0653 (8).
  EXPECT_NEAR(imbalance(charge_profile(64), partition_ring_exact(charge_profile(64), 4)), 1.0584,
              1e-4);
  EXPECT_NEAR(imbalance(charge_profile(128), partition_ring_exact(charge_profile(128), 8)), 1.0653,
              1e-4);
  EXPECT_EQ(imbalance(charge_profile(32), partition_ring_exact(charge_profile(32), 2)), 1.0);
}

TEST(Partition, Deterministic) {
  for (const int nparts : {2, 5, 8, 16}) {
    const std::vector<double> w = charge_profile(16 * nparts);
    const std::vector<double> b = boundaries_of(w);
    const SectorPartition m1 = partition_metis(w, b, nparts), m2 = partition_metis(w, b, nparts);
    EXPECT_EQ(m1.owner, m2.owner);
    EXPECT_EQ(m1.method, m2.method);
    const SectorPartition e1 = partition_ring_exact(w, nparts),
                          e2 = partition_ring_exact(w, nparts);
    EXPECT_EQ(e1.owner, e2.owner);
  }
}

TEST(Partition, FallbacksAndErrors) {
  const std::vector<double> w{1, 2, 3, 4}, b{1, 1, 1, 1};
  const SectorPartition one = partition_metis(w, b, 1);
  expect_contiguous(one, 4, 1);
  EXPECT_EQ(one.method, "ring-exact (fallback: one part)");
  EXPECT_EQ(one.arcs[0].first, 0);
  EXPECT_EQ(one.arcs[0].count, 4);
  const SectorPartition two =
      partition_metis(std::vector<double>{1, 1}, std::vector<double>{1, 1}, 2);
  expect_contiguous(two, 2, 2);
  EXPECT_EQ(two.method, "ring-exact (fallback: fewer than 4 sectors per part)");
  const SectorPartition all = partition_metis(w, b, 4);  // one sector each
  expect_contiguous(all, 4, 4);
  EXPECT_THROW(partition_metis(w, b, 5), std::invalid_argument);
  EXPECT_THROW(partition_ring_exact(w, 0), std::invalid_argument);
  EXPECT_THROW(partition_metis(w, std::vector<double>{1, 1}, 2), std::invalid_argument);
  EXPECT_THROW(partition_ring_exact(std::vector<double>{1, -1, 2}, 2), std::invalid_argument);
  EXPECT_THROW(partition_ring_exact(std::vector<double>{1, NAN, 2}, 2), std::invalid_argument);
}

TEST(Partition, LargeRingIsFast) {
  // n = 4096, 64 parts: well under 100 ms (Release); correctness of the arcs.
  std::vector<double> w(4096);
  for (std::size_t s = 0; s < w.size(); ++s)
    w[s] = (s > 2500 && s < 3900) ? 100.0 + static_cast<double>(s % 17) : 0.5;
  const auto t0 = std::chrono::steady_clock::now();
  const SectorPartition e = partition_ring_exact(w, 64);
  const auto t1 = std::chrono::steady_clock::now();
  const SectorPartition m = partition_metis(w, boundaries_of(w), 64);
  const auto t2 = std::chrono::steady_clock::now();
  const double exact_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  const double metis_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  std::printf("n 4096, 64 parts: ring-exact %.2f ms, metis (incl. exact) %.2f ms, %s\n", exact_ms,
              metis_ms, m.method.c_str());
  EXPECT_LT(exact_ms, 500.0);  // ~1 ms in Release; generous for sanitizer builds
  expect_contiguous(e, 4096, 64);
  expect_contiguous(m, 4096, 64);
  EXPECT_LE(imbalance(w, m), 1.03 + 1e-12);
}

}  // namespace
}  // namespace dem2d
