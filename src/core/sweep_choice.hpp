// Single steps or sweeps of several steps (Simulation::advance), chosen by timing both on the run
// itself. Both give the same bits, so the choice changes only the speed; which is faster depends
// on the charge (how far its store is past the caches), on the machine (its cache sizes) and, on
// a shared host, on the minute (docs/performance.md: at 3e4 particles sweeps took 0.83 of the
// single steps' time in the host's slow minutes and 1.03-1.10 in its quiet ones).
//
// The run is cut into blocks of a fixed number of steps. A trial takes kTrialPairs pairs of
// blocks, one block of each mode per pair, the order alternated from pair to pair; the mode whose
// blocks took less time by the median of the pairs' ratios then runs alone until the next trial:
// kExploitBlocks blocks after a trial that changed the mode, twice as many as last time (at most
// kMostExploitBlocks) after one that kept it. The worse mode so runs at most kTrialPairs of every
// 2 kTrialPairs + kExploitBlocks blocks, and far fewer while the choice holds. Times come from a
// clock given at construction (the thread's CPU time in the program; the tests give their own).
#pragma once

#include <array>
#include <cstdint>
#include <functional>

namespace dem2d {

// The calling thread's CPU time (s): the program's clock for the choice (and the benches').
double thread_cpu_seconds();

class SweepChoice {
 public:
  static constexpr int kTrialPairs = 3;
  static constexpr int kExploitBlocks = 48;
  static constexpr int kMostExploitBlocks = 768;

  using Clock = std::function<double()>;
  SweepChoice(int block_steps, Clock clock);

  // Whether the next steps are swept (true) or taken one at a time, up to the block's end; at a
  // block's start, reads the clock.
  bool next_sweeps();
  // The current block's mode, without reading the clock.
  bool sweeps_now() const { return sweep_now_; }
  // Steps left in the current block (a sweep must not cross it).
  int steps_left() const { return block_steps_ - done_; }
  // `steps` steps were taken in the current mode.
  void stepped(int steps);
  // Trials so far, the mode the last one chose, the trials that chose sweeps, and the blocks the
  // last choice runs for.
  bool chose_sweeps() const { return chose_sweeps_; }
  std::int64_t decisions() const { return decisions_; }
  std::int64_t trials_for_sweeps() const { return for_sweeps_; }
  int exploit_blocks() const { return exploit_blocks_; }

 private:
  void block_done(double seconds);
  void decide();
  int block_steps_ = 0;
  Clock clock_;
  int done_ = 0;          // steps taken in the current block
  double started_ = 0.0;  // the clock at the current block's start
  int trial_block_ = 0;   // within a trial: 0 .. 2 kTrialPairs - 1; then the exploit blocks
  int exploit_left_ = 0;
  int exploit_blocks_ = kExploitBlocks;  // after the last trial
  bool sweep_now_ = false;
  bool chose_sweeps_ = false;
  std::array<double, 2 * kTrialPairs> trial_seconds_{};  // pair p: single 2p, sweeps 2p + 1
  std::int64_t decisions_ = 0, for_sweeps_ = 0;
};

}  // namespace dem2d
