// Storage order (core/fast/spatial_order.hpp): the Hilbert curve visits every cell once, stepping
// to an adjacent cell each time; the sorted store is in curve order; and a run whose particles are
// re-sorted at every rebuild ends with every field of every particle bit for bit as the run kept
// in id order: Verlet and the iterative scheme, a 10:1 size range (several search levels), and
// breakage, feed and sieve changing the population.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <set>

#include "core/contact/contact_kernel.hpp"
#include "core/fast/spatial_order.hpp"
#include "core/run/simulation.hpp"
#include "support/compare.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::expect_same_particles;
using testing_support::thesis_drum_scene;

TEST(SpatialOrder, HilbertCurveVisitsEveryCellOnceByAdjacentSteps) {
  for (int bits = 1; bits <= 6; ++bits) {
    const std::uint32_t side = std::uint32_t{1} << bits;
    std::map<std::uint64_t, std::pair<int, int>> at;
    for (std::uint32_t x = 0; x < side; ++x)
      for (std::uint32_t y = 0; y < side; ++y)
        at[hilbert_index(x, y, bits)] = {static_cast<int>(x), static_cast<int>(y)};
    ASSERT_EQ(at.size(), static_cast<std::size_t>(side) * side) << "bits " << bits;
    EXPECT_EQ(at.begin()->first, 0u);
    EXPECT_EQ(at.rbegin()->first, static_cast<std::uint64_t>(side) * side - 1);
    std::pair<int, int> prev = at.begin()->second;
    for (const auto& [d, xy] : at) {
      if (d == 0) continue;
      EXPECT_EQ(std::abs(xy.first - prev.first) + std::abs(xy.second - prev.second), 1)
          << "bits " << bits << ", step " << d;
      prev = xy;
    }
  }
}

// The storage order is far from id order: the fraction of neighbours in storage that are not
// neighbours in id.
double out_of_id_order(const ParticleStore& p) {
  std::size_t out = 0;
  for (std::size_t k = 1; k < p.n_owned(); ++k) out += p.id[k] < p.id[k - 1];
  return static_cast<double>(out) / static_cast<double>(p.n_owned());
}

// Runs the scene kept in id order and re-sorted at every rebuild, compares at the end; `check`
// then looks at the sorted run.
void expect_sorting_changes_nothing(Scene scene, double t_end,
                                    const std::function<void(const Simulation&)>& check = {}) {
  scene.run.spatial_sort = SpatialSort::kNever;
  Simulation plain(scene);
  scene.run.spatial_sort = SpatialSort::kAlways;
  Simulation sorted(scene);
  plain.run_until(t_end);
  sorted.run_until(t_end);
  EXPECT_EQ(plain.spatial_sorts(), 0);
  EXPECT_GE(sorted.spatial_sorts(), 3) << "the test should sort several times";
  EXPECT_GT(out_of_id_order(sorted.particles()), 0.1) << "the sorted store should be reordered";
  EXPECT_GT(plain.last_totals().contacts, 0);
  EXPECT_EQ(sorted.last_totals().contacts, plain.last_totals().contacts);
  EXPECT_EQ(sorted.neighbor_builds(), plain.neighbor_builds());
  expect_same_particles(plain, sorted);
  if (check) check(sorted);
}

TEST(SpatialOrder, SortingChangesNoBitOfAVerletDrum) {
  expect_sorting_changes_nothing(thesis_drum_scene(120, 1.8, 16, 0.1), 0.25);
}

TEST(SpatialOrder, SortingChangesNoBitOfTheIterativeScheme) {
  Scene s = thesis_drum_scene(60, 1.8, 16, 0.1);
  s.run.integrator = IntegratorKind::kIterative;
  s.run.dt_auto = false;
  s.run.dt = 2e-5;
  expect_sorting_changes_nothing(s, 0.2);
}

// Balls of 2-20 mm radius (four search levels) stirred by an 8-sided drum.
TEST(SpatialOrder, SortingChangesNoBitWithATenToOneSizeRange) {
  const Scene s = testing_support::ten_to_one_drum_scene();
  Simulation probe(s);
  ASSERT_EQ(probe.particles().n_owned(), 200u);
  expect_sorting_changes_nothing(s, 0.4);
}

// Ore breaks, is fed and leaves through the sieve: the population changes between sorts.
TEST(SpatialOrder, SortingChangesNoBitWhileOreBreaksIsFedAndSieved) {
  expect_sorting_changes_nothing(testing_support::grinding_drum_scene(), 0.4,
                                 [](const Simulation& sorted) {
                                   const GrindingTotals& t = sorted.grinding()->totals();
                                   EXPECT_GT(t.breakages, 0);
                                   EXPECT_GT(t.fed_count, 0);
                                   EXPECT_GT(t.discharged_count, 0);
                                 });
}

// Past the caches: from kernels::kScatterPrefetchFrom (50 000) particles on, the canonical scatter
// of a store in id order fetches its partners' lines ahead, which the smaller scenes above never
// do; a sorted store sums force records instead. A square lattice of 52 900 balls of 4 mm, each
// touching its four neighbours and pushed at random, run both ways for 40 steps: every field of
// every particle bit for bit (under the sanitizers too: the lines fetched ahead stay in the list).
TEST(SpatialOrder, SortingChangesNoBitOfAChargePastTheCaches) {
  Scene s = thesis_drum_scene(1, 0.0, 0, 0.0);
  s.fills.clear();
  testing_support::add_pushed_lattice(s, 230, 0.004, 13);
  s.run.spatial_sort = SpatialSort::kNever;
  Simulation plain(s);
  s.run.spatial_sort = SpatialSort::kAlways;
  Simulation sorted(s);
  ASSERT_GE(plain.particles().size(), kernels::kScatterPrefetchFrom);
  for (int k = 0; k < 40; ++k) {
    plain.step();
    sorted.step();
  }
  ASSERT_TRUE(plain.pairs().canonical()) << "the id-ordered store takes the canonical scatter";
  ASSERT_FALSE(sorted.pairs().canonical());
  EXPECT_GE(sorted.spatial_sorts(), 1);
  EXPECT_GT(out_of_id_order(sorted.particles()), 0.1) << "the sorted store should be reordered";
  EXPECT_GT(plain.last_totals().contacts, 90000) << "most lattice bonds should be in contact";
  EXPECT_EQ(sorted.last_totals().contacts, plain.last_totals().contacts);
  expect_same_particles(plain, sorted);
}

// Auto: a small scene is never sorted; a large one when most of its pairs are far apart in
// storage, and again when they have become so after a sort.
TEST(SpatialOrder, AutoSortsLargeScenesWhosePairsAreFarApartInStorage) {
  Scene small = thesis_drum_scene(240, 1.8, 16, 0.1);
  Simulation a(small);
  a.run_until(0.05);
  EXPECT_EQ(a.spatial_sorts(), 0);

  SortPolicy policy;
  const std::size_t big = SortPolicy::kMinParticles;
  EXPECT_FALSE(policy.due(big));  // nothing known about the lists yet
  policy.built(0.9, false);
  EXPECT_FALSE(policy.due(big - 1));
  EXPECT_TRUE(policy.due(big));
  policy.built(0.02, true);
  EXPECT_FALSE(policy.due(big));
  policy.built(0.5, false);
  EXPECT_TRUE(policy.due(big));
  EXPECT_EQ(policy.sorts(), 1);
}

}  // namespace
}  // namespace dem2d
