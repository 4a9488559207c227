// Resuming a run (core/run/run_state.hpp): a simulation rebuilt from another's particles, contact
// histories and run state continues bit for bit as the original does, for both integrators and
// through breakage, feed and sieve. (The checkpoint file and the rank counts: tests/io and the
// cli tests.)
#include <gtest/gtest.h>

#include <numeric>

#include "core/run/simulation.hpp"
#include "support/compare.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::expect_same_particles;
using testing_support::thesis_drum_scene;

// What a checkpoint would hold of `sim` (one rank: every particle is owned here).
Resumption resumption_of(const Simulation& sim) {
  Resumption r;
  r.state = sim.run_state();
  const ParticleStore& p = sim.particles();
  r.n_particles = p.n_owned();
  std::vector<std::int32_t> all(p.n_owned());
  std::iota(all.begin(), all.end(), 0);
  for (const FieldBase* f : p.fields()) {
    std::vector<std::byte> bytes(p.n_owned() * f->bytes_per_item());
    f->pack_items(all, bytes.data());
    r.columns.push_back(std::move(bytes));
  }
  r.histories = sim.histories();
  return r;
}

void expect_same_ledger(const Simulation& a, const Simulation& b) {
  const SeriesRow r = a.diagnostics(), s = b.diagnostics();
  EXPECT_EQ(r.step, s.step);
  EXPECT_EQ(r.time, s.time);
  EXPECT_EQ(r.contacts, s.contacts);
  EXPECT_EQ(r.dissipated_energy, s.dissipated_energy);
  EXPECT_EQ(r.drive_work, s.drive_work);
  EXPECT_EQ(r.elastic_energy, s.elastic_energy);
  EXPECT_EQ(r.drum_torque, s.drum_torque);
  EXPECT_EQ(a.passes_total(), b.passes_total());
  // (Not the neighbour builds: the resumed run builds its lists at other steps, and that
  // changes no bit of the particles.)
}

// Runs `scene` to t_stop, resumes a copy from there, runs both to t_end and compares.
void check_resume(const Scene& scene, double t_stop, double t_end) {
  Simulation original(scene);
  original.run_until(t_stop);
  const Resumption r = resumption_of(original);
  ASSERT_GT(r.histories.size(), 0u) << "the test should resume with contacts in progress";
  Simulation resumed(scene, nullptr, &r);
  EXPECT_EQ(resumed.time(), original.time());
  EXPECT_EQ(resumed.dt(), original.dt());
  original.run_until(t_end);
  resumed.run_until(t_end);
  expect_same_particles(original, resumed);
  expect_same_ledger(original, resumed);
}

TEST(Resume, VerletDrumContinuesBitForBitDuringTheRamp) {
  check_resume(thesis_drum_scene(120, 1.8, 16, 0.5), 0.2, 0.45);
}

// The comparison can fail: resumed without its contact histories (tangential springs, rolling
// states), the same run drifts away.
TEST(Resume, WithoutTheHistoriesTheRunDiffers) {
  const Scene s = thesis_drum_scene(120, 1.8, 16, 0.5);
  Simulation original(s);
  original.run_until(0.2);
  Resumption r = resumption_of(original);
  r.histories = HistoryRecords(r.histories.width());
  Simulation resumed(s, nullptr, &r);
  original.run_until(0.3);
  resumed.run_until(0.3);
  const ParticleStore& p = original.particles();
  const ParticleStore& q = resumed.particles();
  int moved = 0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    for (std::size_t m = 0; m < q.n_owned(); ++m)
      if (q.id[m] == p.id[k]) moved += q.pos[m] != p.pos[k];
  EXPECT_GT(moved, 10);
}

// Ellipses (the store's shape fields, the superellipse's warm-start slots in the histories).
TEST(Resume, EllipsesContinueBitForBit) {
  check_resume(testing_support::shaped_drum_scene(100, 0.6, 1.0, true), 0.12, 0.15);
}

TEST(Resume, IterativeDrumContinuesBitForBit) {
  Scene s = thesis_drum_scene(60, 1.8, 16, 0.1);
  s.run.integrator = IntegratorKind::kIterative;
  s.run.dt_auto = false;
  s.run.dt = 2e-5;
  check_resume(s, 0.15, 0.3);
}

// Ore in the drum with the balls: it breaks, is fed and leaves through the sieve before and
// after the restart; ids, counts and the energies fed and discharged continue.
TEST(Resume, GrindingContinuesBitForBitThroughBreakageFeedAndSieve) {
  Scene s = testing_support::grinding_drum_scene();
  Simulation original(s);
  original.run_until(0.3);
  const GrindingTotals& t = original.grinding()->totals();
  ASSERT_GT(t.breakages, 0);
  ASSERT_GT(t.fed_count, 0);
  check_resume(s, 0.3, 0.6);
}

// The size-aware ore: damage in J/kg, t10 progeny and their fines, the grate; the size
// distributions (feed, product) continue too.
TEST(Resume, SizeAwareOreContinuesBitForBitWithItsSizes) {
  Scene s = testing_support::grinding_drum_scene();
  BreakageSpec& b = s.breakage;
  b.model = BreakageModel::kVogelPeukert;
  b.f_mat = 50.0;
  b.xw_min = 0.01;
  b.fragments = FragmentLaw::kT10;
  b.t10_a = 60.0;
  b.t10_b = 30.0;
  b.fines_diameter = 0.02;
  Simulation original(s);
  original.run_until(0.3);
  ASSERT_GT(original.grinding()->totals().breakages, 0);
  ASSERT_GT(original.grinding()->totals().fines_mass, 0.0);
  check_resume(s, 0.3, 0.6);
  Simulation again(s);
  again.run_until(0.3);
  const Resumption r = resumption_of(again);
  Simulation resumed(s, nullptr, &r);
  again.run_until(0.6);
  resumed.run_until(0.6);
  const GrindingSizes x = again.grinding()->state().sizes, y = resumed.grinding()->state().sizes;
  for (int k = 0; k < SizeMasses::kClasses; ++k) {
    EXPECT_EQ(x.fed.units()[k], y.fed.units()[k]);
    EXPECT_EQ(x.product.units()[k], y.product.units()[k]);
  }
  EXPECT_GT(x.product.total_kg(), 0.0);
}

}  // namespace
}  // namespace dem2d
