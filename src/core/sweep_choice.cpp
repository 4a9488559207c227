#include "core/sweep_choice.hpp"

#include <time.h>

#include <algorithm>
#include <utility>

namespace dem2d {

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

namespace {
// Trial block b: pair b / 2, single steps first in even pairs, sweeps first in odd ones.
bool trial_sweeps(int b) { return (b % 2 == 1) != ((b / 2) % 2 == 1); }
}  // namespace

SweepChoice::SweepChoice(int block_steps, Clock clock)
    : block_steps_(block_steps), clock_(std::move(clock)), sweep_now_(trial_sweeps(0)) {}

bool SweepChoice::next_sweeps() {
  if (done_ == 0) started_ = clock_();
  return sweep_now_;
}

void SweepChoice::stepped(int steps) {
  done_ += steps;
  if (done_ < block_steps_) return;
  done_ = 0;
  block_done(clock_() - started_);
}

void SweepChoice::block_done(double seconds) {
  if (trial_block_ < 2 * kTrialPairs) {
    trial_seconds_[static_cast<std::size_t>(2 * (trial_block_ / 2) + (sweep_now_ ? 1 : 0))] =
        seconds;
    if (++trial_block_ < 2 * kTrialPairs) {
      sweep_now_ = trial_sweeps(trial_block_);
      return;
    }
    decide();
    exploit_left_ = exploit_blocks_;
    sweep_now_ = chose_sweeps_;
    return;
  }
  if (--exploit_left_ > 0) return;
  trial_block_ = 0;
  sweep_now_ = trial_sweeps(0);
}

// The median over the pairs of sweeps' time over single steps' time.
void SweepChoice::decide() {
  std::array<double, kTrialPairs> ratio{};
  for (std::size_t p = 0; p < ratio.size(); ++p)
    ratio[p] = trial_seconds_[2 * p + 1] / trial_seconds_[2 * p];
  std::sort(ratio.begin(), ratio.end());
  const bool sweeps = ratio[ratio.size() / 2] < 1.0;
  exploit_blocks_ = decisions_ > 0 && sweeps == chose_sweeps_
                        ? std::min(2 * exploit_blocks_, kMostExploitBlocks)
                        : kExploitBlocks;
  chose_sweeps_ = sweeps;
  ++decisions_;
  for_sweeps_ += chose_sweeps_ ? 1 : 0;
}

}  // namespace dem2d
