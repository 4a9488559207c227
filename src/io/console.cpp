#include "io/console.hpp"

#include <unistd.h>

#include "parallel/comm.hpp"

namespace dem2d {

void say(const std::string& text, FILE* stream) {
  if (mpi::rank(MPI_COMM_WORLD) == 0) {
    std::fputs(text.c_str(), stream);
    std::fflush(stream);
  }
}

Progress::Progress(bool quiet, double duration, double interval, std::int64_t first_step)
    : first_step_(first_step),
      quiet_(quiet),
      tty_(isatty(STDERR_FILENO) != 0),
      active_(mpi::rank(MPI_COMM_WORLD) == 0),
      duration_(duration),
      interval_(interval),
      start_(Clock::now()),
      last_(start_) {}

void Progress::update(const Simulation& sim, std::int64_t particles, double particle_steps,
                      bool final_line) {
  if (quiet_ || !active_) return;
  const auto now = Clock::now();
  const double since = std::chrono::duration<double>(now - last_).count();
  if (!final_line && since < (tty_ ? 0.5 : interval_)) return;
  last_ = now;
  const double wall = std::chrono::duration<double>(now - start_).count();
  const double rate = wall > 0 ? particle_steps / wall : 0;
  const double t0 = static_cast<double>(first_step_) * sim.dt();
  const double frac = (sim.time() - t0) / (duration_ - t0);
  const double eta = frac > 0 ? std::max(0.0, wall * (1.0 - frac) / frac) : 0.0;
  char line[256];
  std::snprintf(line, sizeof line,
                "step %lld  t = %.4f / %.4g s  particles %lld  %.3g particle-steps/s  ETA %.0f s",
                static_cast<long long>(sim.step_count()), sim.time(), duration_,
                static_cast<long long>(particles), rate, eta);
  if (tty_)
    std::fprintf(stderr, "\r%s\033[K%s", line, final_line ? "\n" : "");
  else
    std::fprintf(stderr, "%s\n", line);
  std::fflush(stderr);
}

}  // namespace dem2d
