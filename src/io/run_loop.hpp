// The time loop of a run with its outputs: series rows, snapshots and checkpoints at their
// intervals, the first state (not on a restart: the interrupted run wrote it) and the last one
// always; the guards' warnings; a stop on SIGINT or SIGTERM, agreed on by every rank.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "core/step/domain.hpp"
#include "io/console.hpp"
#include "io/run_outputs.hpp"
#include "io/snapshots.hpp"

namespace dem2d {

// SIGINT and SIGTERM (mpirun passes SIGTERM on to every rank) ask the run to stop. The flag
// is read every kStopPollSteps steps in one reduction, so every rank stops after the same
// step; the run then writes its checkpoint, last snapshot and run.json and exits with
// kExitInterrupted. The handler resets itself: a second signal ends the process at once (the
// checkpoint on disk is then the previous one, whole).
void install_stop_handlers();
inline constexpr std::int64_t kStopPollSteps = 100;

enum class Ending { kFinished, kUnstable, kInterrupted };

class RunLoop {
 public:
  using Clock = std::chrono::steady_clock;
  // `resumed`: a restart (--restart), continuing from the checkpoint's state.
  RunLoop(Simulation& sim, const Scene& scene, Domain& domain, SeriesOutput& series,
          SnapshotWriter& snapshots, bool resumed);
  // Collective: steps to run.duration or until stopped. kUnstable: an UnstableError, told on
  // stderr after the last snapshot was written.
  Ending run(Progress& progress);
  // The signal that stopped the run (kInterrupted).
  int stop_signal() const { return stop_signal_; }
  // Over every rank: the particles now and the particle-steps taken by this run (each step's
  // count of owned particles summed; a restart counts from where it continued). Exact after
  // run() returns, as of the last poll while it runs.
  std::int64_t particles() const { return particles_; }
  std::int64_t particle_steps() const { return particle_steps_; }
  // The warnings the run gave while it ran (told on stderr too), for run.json.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // lifters.csv and the shell (its model and last response on rank 0).
  const LifterOutput& lifters() const { return lifters_; }
  // Above this bed filling a fed mill is told that its charge is filling the drum (the charge
  // then reaches past the drum centre: no mill runs so full).
  static constexpr double kFillWarning = 0.5;

 private:
  // The outputs due at time t: one test for the step that acts on them (after_step, finish)
  // and for the one that predicts them (observes_step).
  struct Due {
    bool series, snapshot, checkpoint;
    bool any() const { return series || snapshot || checkpoint; }
  };
  bool at_multiple(double t, double interval) const;
  Due due_at(double t) const;
  static bool polls_at(std::int64_t step) { return step % kStopPollSteps == 0; }
  // Whether anything reads the particles after the coming step: an output or checkpoint due at
  // its time, the stop poll, the end of the run (else the step may run ahead: Simulation::step).
  bool observes_step(std::int64_t next) const;
  void snapshot();
  void checkpoint();
  void after_step();
  // The poll: a stop signal on any rank, and rank 0's clock for output.checkpoint_minutes.
  bool stop_requested();
  // Collective: particles() and particle_steps() from every rank's counts.
  void count_particles();
  // The particle-steps for the progress line: exact at the last poll, the count then for the
  // steps since.
  double particle_steps_now() const;
  Ending finish(Ending ending);
  // Collective, at series rows of a fed drum: the warning, once, when the bed filling passes
  // kFillWarning.
  void watch_fill();

  Simulation& sim_;
  const Scene& scene_;
  Domain& domain_;
  SeriesOutput& series_;
  SnapshotWriter& snapshots_;
  OreOutput ore_;
  LifterOutput lifters_;
  bool resumed_;
  Clock::time_point last_checkpoint_;
  double last_snapshot_time_ = -1.0;
  std::int64_t checkpoint_step_ = -1;  // the step of the last checkpoint written
  std::size_t guards_told_ = 0;        // run.guards = "warn": each kind is told when it first fires
  int stop_signal_ = 0;
  std::int64_t local_particle_steps_ = 0;  // this rank's owned particles summed over the steps
  std::int64_t particles_ = 0, particle_steps_ = 0, counted_at_step_ = 0;
  std::vector<std::string> warnings_;
  bool fill_told_ = false;
};

}  // namespace dem2d
