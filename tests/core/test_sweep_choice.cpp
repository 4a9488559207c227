// The timed choice between single steps and sweeps (core/sweep_choice.hpp), driven by a clock the
// test sets: the trial's order of blocks, the choice by the median of the pairs, the exploit
// blocks doubling while the choice holds and reset when it changes, and blocks that sweeps never
// cross. (That the choice changes no bit of a run: test_paired_steps.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/sweep_choice.hpp"

namespace dem2d {
namespace {

// A clock read at each block's start and end: a block of single steps costs `single`, one of
// sweeps `sweep` (per block, in seconds); `outlier` > 0 makes that trial block cost it instead.
struct FakeClock {
  const SweepChoice* choice = nullptr;
  double now = 0.0, single = 1.0, sweep = 1.0;
  int calls = 0;
  double operator()() {
    if (calls++ % 2 == 1) now += choice->sweeps_now() ? sweep : single;  // a block's end
    return now;
  }
};

// Steps whole blocks (single steps one at a time, sweeps of up to 8) and returns each block's mode.
std::vector<bool> run_blocks(SweepChoice& c, int blocks) {
  std::vector<bool> modes;
  for (int b = 0; b < blocks; ++b) {
    modes.push_back(c.next_sweeps());  // the block's start: the clock is read
    while (true) {
      EXPECT_EQ(c.sweeps_now(), modes.back()) << "a block keeps its mode";
      const int left = c.steps_left();
      const int steps = modes.back() ? std::min(8, left) : 1;
      c.stepped(steps);
      if (steps == left) break;
    }
  }
  return modes;
}

constexpr int kTrial = 2 * SweepChoice::kTrialPairs;

TEST(SweepChoice, TrialBlocksAlternateTheModesAndTheOrderWithinPairs) {
  FakeClock clock;
  SweepChoice c(20, [&] { return clock(); });
  clock.choice = &c;
  const std::vector<bool> modes = run_blocks(c, kTrial);
  // Pairs: single then sweeps, sweeps then single, single then sweeps.
  EXPECT_EQ(modes, (std::vector<bool>{false, true, true, false, false, true}));
  EXPECT_EQ(c.decisions(), 1);
  EXPECT_EQ(clock.calls, 2 * kTrial) << "the clock is read at each block's start and end";
}

TEST(SweepChoice, ChoosesTheFasterModeAndKeepsItForTheExploitBlocks) {
  for (const bool sweeps_faster : {true, false}) {
    FakeClock clock;
    clock.sweep = sweeps_faster ? 0.8 : 1.25;
    SweepChoice c(24, [&] { return clock(); });
    clock.choice = &c;
    run_blocks(c, kTrial);
    EXPECT_EQ(c.chose_sweeps(), sweeps_faster);
    EXPECT_EQ(c.trials_for_sweeps(), sweeps_faster ? 1 : 0);
    const std::vector<bool> exploit = run_blocks(c, SweepChoice::kExploitBlocks);
    for (const bool m : exploit) EXPECT_EQ(m, sweeps_faster);
    // Then a new trial, single steps first.
    EXPECT_FALSE(run_blocks(c, 1).front());
  }
}

TEST(SweepChoice, OneSlowPairDoesNotTurnTheChoice) {
  FakeClock clock;
  clock.sweep = 0.9;
  SweepChoice c(16, [&] { return clock(); });
  clock.choice = &c;
  run_blocks(c, 2);   // pair 1: sweeps 0.9 of single
  clock.sweep = 3.0;  // pair 2: a slow minute falls on its sweeps
  run_blocks(c, 2);
  clock.sweep = 0.9;  // pair 3
  run_blocks(c, 2);
  EXPECT_TRUE(c.chose_sweeps()) << "the median of 0.9, 3 and 0.9 is 0.9";
}

TEST(SweepChoice, ExploitBlocksDoubleWhileTheChoiceHoldsAndResetWhenItTurns) {
  FakeClock clock;
  clock.sweep = 0.5;
  SweepChoice c(8, [&] { return clock(); });
  clock.choice = &c;
  std::vector<int> exploit;
  for (int trial = 0; trial < 6; ++trial) {
    run_blocks(c, kTrial);
    exploit.push_back(c.exploit_blocks());
    run_blocks(c, c.exploit_blocks());
  }
  const int e = SweepChoice::kExploitBlocks;
  EXPECT_EQ(exploit, (std::vector<int>{e, 2 * e, 4 * e, 8 * e, SweepChoice::kMostExploitBlocks,
                                       SweepChoice::kMostExploitBlocks}));
  EXPECT_EQ(c.trials_for_sweeps(), 6);
  clock.sweep = 2.0;  // sweeps now slower: the choice turns and the exploit blocks reset
  run_blocks(c, kTrial);
  EXPECT_FALSE(c.chose_sweeps());
  EXPECT_EQ(c.exploit_blocks(), e);
}

TEST(SweepChoice, SweepsNeverCrossABlocksEnd) {
  FakeClock clock;
  clock.sweep = 0.5;
  SweepChoice c(20, [&] { return clock(); });
  clock.choice = &c;
  run_blocks(c, kTrial);  // sweeps chosen
  ASSERT_TRUE(c.next_sweeps());
  std::vector<int> left;
  for (int k = 0; k < 3; ++k) {
    left.push_back(c.steps_left());
    c.stepped(std::min(8, c.steps_left()));
  }
  EXPECT_EQ(left, (std::vector<int>{20, 12, 4}));
  EXPECT_EQ(c.steps_left(), 20) << "the next block starts whole";
}

}  // namespace
}  // namespace dem2d
