// What the program tells its user on the terminal: messages (rank 0 alone prints them, every
// rank may call) and the progress line of a run.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/run/simulation.hpp"

namespace dem2d {

// Writes `text` to `stream` on rank 0 of MPI_COMM_WORLD and flushes it; nothing elsewhere.
void say(const std::string& text, FILE* stream = stdout);

// The progress line on stderr (rank 0, unless quiet): step, time, particles now, particle-steps
// per second (the particle count of every step summed, births and discharges included) and the
// time left. On a terminal one line rewritten at most every 0.5 s; else a
// line every `interval` seconds of wall time.
class Progress {
 public:
  using Clock = std::chrono::steady_clock;
  // `first_step`: the step the run starts from (a restart continues the count).
  Progress(bool quiet, double duration, double interval, std::int64_t first_step);
  // `final_line`: the run's last line, written whatever the time since the previous one.
  // `particles`: over every rank now; `particle_steps`: since the run started here.
  void update(const Simulation& sim, std::int64_t particles, double particle_steps,
              bool final_line = false);

 private:
  std::int64_t first_step_;
  bool quiet_, tty_, active_;
  double duration_, interval_;
  Clock::time_point start_, last_;
};

}  // namespace dem2d
