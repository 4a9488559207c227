// Steps in one sweep (Simulation::advance, VelocityVerlet::sweep_steps,
// ContactKernel::evaluate_sweep): each step's pair loop follows the one before through the
// store, each particle closed and drifted as soon as its forces are complete. A run stepped two,
// three, four or eight steps per sweep must end bit for bit as the run stepped one step at a time:
// every field of every particle, the energy ledger, the totals, the contacts and the rebuilds.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include "core/simulation.hpp"
#include "support/compare.hpp"
#include "support/random_store.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::expect_same_particles;
using testing_support::same_bits;
using testing_support::thesis_drum_scene;

constexpr std::size_t kNever = std::numeric_limits<std::size_t>::max();

bool never(int) { return false; }

// The program's own number of steps per sweep (Simulation::sweep_steps unset).
constexpr int kProgramsSweep = 0;

// Both runs to each time in `times`, compared there: every field of every particle, the ledger,
// the totals and the rebuilds, bit for bit.
void run_both_to(Simulation& single, Simulation& other, std::initializer_list<double> times) {
  for (const double t : times) {
    SCOPED_TRACE(testing::Message() << "t = " << t);
    single.run_until(t);
    other.run_until(t);
    ASSERT_EQ(other.step_count(), single.step_count());
    expect_same_particles(single, other);
    testing_support::expect_same_ledger(single, other);
    const EvaluationTotals& x = other.last_totals();
    const EvaluationTotals& y = single.last_totals();
    EXPECT_EQ(x.contacts, y.contacts);
    EXPECT_TRUE(same_bits(x.drum_torque, y.drum_torque));
    EXPECT_TRUE(same_bits(x.drive_power, y.drive_power));
    EXPECT_TRUE(same_bits(x.max_overlap, y.max_overlap));
    EXPECT_EQ(other.neighbor_builds(), single.neighbor_builds());
  }
}

// Both runs to each time in `times`, one in sweeps of up to `sweep` steps (kProgramsSweep: the
// program's default) whenever allowed, one a step at a time.
void expect_sweeps_change_nothing(const Scene& scene, std::initializer_list<double> times,
                                  int sweep, std::int64_t min_builds = 4) {
  Simulation single(scene), paired(scene);
  single.set_pair_steps_from(kNever);
  paired.set_pair_steps_from(0);
  if (sweep == kProgramsSweep)
    sweep = paired.sweep_steps();
  else
    paired.set_sweep_steps(sweep);
  SCOPED_TRACE(testing::Message() << "up to " << sweep << " steps per sweep");
  run_both_to(single, paired, times);
  std::cout << "[ swept    ] " << paired.steps_paired() << " of " << paired.step_count()
            << " steps in sweeps of up to " << sweep << " (" << paired.sweeps_of(sweep) << " of "
            << sweep << "), " << single.neighbor_builds() << " rebuilds, "
            << paired.particles().n_owned() << " particles\n";
  EXPECT_EQ(single.steps_paired(), 0);
  EXPECT_GT(paired.steps_paired(), paired.step_count() / 2) << "most steps should be swept";
  EXPECT_GT(sweep * paired.sweeps_of(sweep), paired.steps_paired() / 2)
      << "most sweeps should be of the longest";
  EXPECT_GE(single.neighbor_builds(), min_builds) << "the run should rebuild between pairs";
  EXPECT_GT(single.diagnostics().dissipated_energy, 0.0);
}

// Hertz-Mindlin with the EPSD rolling model (two history slots written in place), 400 balls in
// a 16-sided drum whose speed ramps up (the drive's power and torque at each step's own pose
// and speed), filled to the top: balls land, tumble and touch the shell.
Scene rolling_drum_scene() {
  Scene s = thesis_drum_scene(400, 1.8, 16, 0.1);
  s.contact.model = ContactModelKind::kHertzMindlin;
  s.contact.rolling = RollingModelKind::kEpsd;
  s.fills.front().radius_min = 0.05;
  s.fills.front().radius_max = 0.08;
  return s;
}

TEST(PairedSteps, HertzMindlinWithRollingEndsBitForBitAsStepByStep) {
  for (const int sweep : {2, 3, 4, kProgramsSweep})
    expect_sweeps_change_nothing(rolling_drum_scene(), {0.05, 0.1234, 0.2}, sweep);
}

// The program's timed choice between single steps and sweeps (core/sweep_choice.hpp) on the same
// drum, with a clock that makes each trial choose the other mode than the one before: the run
// switches between the modes at block ends, inside a sweep's reach, and must still end bit for
// bit as the run stepped one step at a time.
TEST(PairedSteps, TheTimedChoiceOfModesEndsBitForBitAsStepByStep) {
  const Scene s = rolling_drum_scene();
  Simulation single(s), timed(s);
  single.set_pair_steps_from(kNever);
  double now = 0.0;
  int calls = 0;
  timed.set_sweep_choice(0, 12, [&] {
    if (calls++ % 2 == 1) {  // a block's end: the mode the last trial did not choose is faster
      const SweepChoice& c = *timed.sweep_choice();
      const bool favour_sweeps = c.decisions() % 2 == 0;
      now += c.sweeps_now() == favour_sweeps ? 1.0 : 2.0;
    }
    return now;
  });
  run_both_to(single, timed, {0.05, 0.1234, 0.2});
  const SweepChoice& c = *timed.sweep_choice();
  std::cout << "[ timed    ] " << timed.steps_paired() << " of " << timed.step_count()
            << " steps in sweeps; " << c.decisions() << " trials, " << c.trials_for_sweeps()
            << " chose sweeps\n";
  EXPECT_GE(c.decisions(), 4);
  EXPECT_GE(c.trials_for_sweeps(), 2);
  EXPECT_GE(c.decisions() - c.trials_for_sweeps(), 2);
  EXPECT_GT(timed.steps_paired(), timed.step_count() / 4);
  EXPECT_LT(timed.steps_paired(), timed.step_count() * 3 / 4);
}

// A square lattice of 4 900 touching balls of 4 mm, pushed at random, in a circular drum that
// its corners touch, turning up to speed: the pair list has some 25 chunks, so each later
// step's loop runs behind the one before through the whole store and hands particles over in
// many ranges (the scenes above have one or two chunks).
TEST(PairedSteps, ALatticeOfManyChunksEndsBitForBitAsStepByStep) {
  Scene s = thesis_drum_scene(1, 1.8, 0, 0.01);
  s.contact.model = ContactModelKind::kHertzMindlin;
  s.contact.rolling = RollingModelKind::kEpsd;
  s.fills.clear();
  constexpr int kSide = 70;
  constexpr double kR = 0.004;
  testing_support::add_pushed_lattice(s, kSide, kR, 17);
  // The corner balls just touch the shell.
  s.drum.radius = std::sqrt(2.0) * 0.5 * (kSide - 1) * 2.0 * kR * (1.0 - 1e-4) + 0.999 * kR;
  Simulation probe(s);
  const double dt = probe.dt();
  for (const int sweep : {2, 3, 4, kMaxSweepSteps})
    expect_sweeps_change_nothing(s, {101.5 * dt, 250.5 * dt, 400.5 * dt}, sweep, 2);
}

// The thesis's law without history, in a circular shell.
TEST(PairedSteps, TheThesisLawEndsBitForBitAsStepByStep) {
  Scene s = thesis_drum_scene(300, 1.8, 0, 0.1);
  s.contact.model = ContactModelKind::kThesis;
  s.contact.rolling = RollingModelKind::kNone;
  s.fills.front().radius_min = s.fills.front().radius_max = 0.06;
  s.run.guards_warn = true;  // this law creates energy in a drum (test_pair_gather.cpp)
  for (const int sweep : {2, 3, kProgramsSweep})
    expect_sweeps_change_nothing(s, {0.05, 0.13}, sweep);
}

// A pile of soft balls in a slow drum overlaps past a quarter of a radius as it settles: the
// overlap guard fires. Where the guard fires at a step of a sweep but its last it must name that
// step, at its time, with its overlap, as the run stepped one step at a time does; with
// run.guards = "warn" both runs go on and end alike, with "stop" both stop with the same
// error, and the state left for the failure snapshot carries its own step and time. Eight
// stiffnesses, in sweeps of up to 2 and 3 steps; with a wide skin most fire within a sweep.
std::string guard_of_stopped_run(Scene s, std::size_t pair_from, int sweep) {
  s.run.guards_warn = false;
  Simulation sim(s);
  sim.set_pair_steps_from(pair_from);
  sim.set_sweep_steps(sweep);
  try {
    for (int k = 0; k < 4000; ++k) sim.advance(never);
  } catch (const UnstableError& e) {
    // The state the failure snapshot shows is labelled with its own step and time.
    EXPECT_EQ(sim.time(), static_cast<double>(sim.step_count()) * sim.dt());
    return std::to_string(e.step()) + ": " + e.what();
  }
  return "";
}

TEST(PairedSteps, AGuardThatFiresInASweepNamesItsStepAsStepByStep) {
  for (const int sweep : {2, 3}) {
    SCOPED_TRACE(testing::Message() << "up to " << sweep << " steps per sweep");
    int fired_early = 0;
    for (const double young : {3e4, 4e4, 6e4, 1e5, 1.5e5, 2e5, 3e5, 5e5}) {
      SCOPED_TRACE(testing::Message() << "E = " << young);
      Scene s = thesis_drum_scene(200, 0.5, 0, 0.1);
      s.contact.model = ContactModelKind::kHertzMindlin;
      s.contact.rolling = RollingModelKind::kEpsd;
      s.materials.front().youngs_modulus = young;
      s.materials.front().shear_modulus = young / 2.5;
      s.run.guards_warn = true;
      s.run.duration = 100.0;
      s.run.skin = 0.4;  // wide: the falling balls' steps pair too
      Simulation single(s), paired(s);
      single.set_pair_steps_from(kNever);
      paired.set_pair_steps_from(0);
      paired.set_sweep_steps(sweep);
      std::int64_t until = 60;  // a few steps past the first guard (then the balls leave)
      while (paired.step_count() < until) {
        const std::int64_t before = paired.step_count();
        const bool quiet = paired.guard_records().empty();
        const int taken = paired.advance(never);
        for (int k = 1; k < taken; ++k)
          if (quiet && !paired.guard_records().empty() &&
              paired.guard_records()[0].first.find("at step " + std::to_string(before + k) + " ") !=
                  std::string::npos)
            ++fired_early;
        if (quiet && !paired.guard_records().empty()) until = paired.step_count() + 3;
      }
      while (single.step_count() < paired.step_count()) single.advance(never);
      ASSERT_EQ(single.step_count(), paired.step_count());
      ASSERT_FALSE(single.guard_records().empty());
      ASSERT_EQ(paired.guard_records().size(), single.guard_records().size());
      for (std::size_t g = 0; g < single.guard_records().size(); ++g) {
        EXPECT_EQ(paired.guard_records()[g].kind, single.guard_records()[g].kind);
        EXPECT_EQ(paired.guard_records()[g].count, single.guard_records()[g].count);
        EXPECT_EQ(paired.guard_records()[g].first, single.guard_records()[g].first);
      }
      single.run_until(single.time() + 0.5 * single.dt());  // ends whole
      paired.run_until(paired.time() + 0.5 * paired.dt());
      expect_same_particles(single, paired);
      EXPECT_GT(paired.steps_paired(), 0);
      const std::string stopped = guard_of_stopped_run(s, kNever, sweep);
      EXPECT_FALSE(stopped.empty());
      EXPECT_EQ(guard_of_stopped_run(s, 0, sweep), stopped);
    }
    EXPECT_GE(fired_early, 1) << "no guard fired at a step of a sweep but its last";
  }
}

}  // namespace
}  // namespace dem2d
