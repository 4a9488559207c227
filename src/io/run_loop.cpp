#include "io/run_loop.hpp"

#include <fmt/format.h>
#include <signal.h>

#include <cmath>
#include <csignal>
#include <optional>
#include <span>
#include <string>

#include "core/base/errors.hpp"
#include "core/mill/mill_analytics.hpp"
#include "io/checkpoint.hpp"
#include "io/collisions.hpp"
#include "io/output_dir.hpp"
#include "parallel/comm.hpp"

namespace dem2d {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void on_stop_signal(int signo) { g_stop_signal = signo; }

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

RunLoop::RunLoop(Simulation& sim, const Scene& scene, Domain& domain, SeriesOutput& series,
                 SnapshotWriter& snapshots, bool resumed)
    : sim_(sim),
      scene_(scene),
      domain_(domain),
      series_(series),
      snapshots_(snapshots),
      ore_(scene, sim, resumed),
      lifters_(scene, sim, resumed),
      resumed_(resumed),
      last_checkpoint_(Clock::now()) {}

bool RunLoop::at_multiple(double t, double interval) const {
  if (interval <= 0.0) return false;
  const double k = std::round(t / interval);
  return std::abs(t - k * interval) < 0.5 * sim_.dt();
}

RunLoop::Due RunLoop::due_at(double t) const {
  const OutputSpec& out = scene_.output;
  return {at_multiple(t, out.series_interval), at_multiple(t, out.snapshot_interval),
          at_multiple(t, out.checkpoint_interval)};
}

bool RunLoop::observes_step(std::int64_t next) const {
  const double t = static_cast<double>(next) * sim_.dt();  // Simulation::advance_clock's
  return polls_at(next) || t + 0.5 * sim_.dt() >= scene_.run.duration || due_at(t).any();
}

void RunLoop::snapshot() {
  const std::optional<ShellField> field = lifters_.shell_field(sim_);  // rank 0's
  ShellSnapshot shell;
  if (field) {
    const FeMesh& mesh = lifters_.shell()->model().mesh();
    shell = {field->position, field->displacement, field->von_mises, mesh.elements,
             mesh.element_bar};
  }
  snapshots_.write(sim_.particles(), sim_.time(), sim_.step_count(), wall_outlines(sim_.walls()),
                   {}, field ? &shell : nullptr);
  last_snapshot_time_ = sim_.time();
  if (sim_.spectra()) write_collisions(MPI_COMM_WORLD, scene_.output.directory, *sim_.spectra());
}

// The logs' records up to now first: a restart keeps the rows up to the checkpoint's time.
void RunLoop::checkpoint() {
  ore_.write(sim_);
  write_checkpoint(MPI_COMM_WORLD, scene_.output.directory + "/" + kCheckpointFile, sim_);
  last_checkpoint_ = Clock::now();
  checkpoint_step_ = sim_.step_count();
}

void RunLoop::count_particles() {
  std::int64_t counts[2] = {static_cast<std::int64_t>(sim_.particles().n_owned()),
                            local_particle_steps_};
  domain_.sum(std::span<std::int64_t>(counts));
  particles_ = counts[0];
  particle_steps_ = counts[1];
  counted_at_step_ = sim_.step_count();
}

double RunLoop::particle_steps_now() const {
  return static_cast<double>(particle_steps_) +
         static_cast<double>(particles_) *
             static_cast<double>(sim_.step_count() - counted_at_step_);
}

Ending RunLoop::run(Progress& progress) {
  const OutputSpec& out = scene_.output;
  count_particles();
  if (!resumed_) {
    series_.write(sim_.record_row());
    lifters_.write(sim_);
    sim_.reset_pass_window();
    if (out.snapshot_interval > 0) snapshot();
  }
  try {
    while (sim_.time() + 0.5 * sim_.dt() < scene_.run.duration) {
      sim_.step(observes_step(sim_.step_count() + 1));
      local_particle_steps_ += static_cast<std::int64_t>(sim_.particles().n_owned());
      after_step();
      if (polls_at(sim_.step_count())) {
        count_particles();
        if (stop_requested()) return finish(Ending::kInterrupted);
      }
      progress.update(sim_, particles_, particle_steps_now());
    }
  } catch (const UnstableError& e) {
    ore_.write(sim_);
    snapshots_.write(sim_.particles(), sim_.time(), sim_.step_count(), wall_outlines(sim_.walls()));
    say(scene_.deck_path + ": error: " + e.what() + "; last snapshot written to " + out.directory +
            "/" + kSnapshotsFile + "\n",
        stderr);
    return Ending::kUnstable;
  }
  const Ending ending = finish(Ending::kFinished);
  progress.update(sim_, particles_, static_cast<double>(particle_steps_), true);
  return ending;
}

void RunLoop::after_step() {
  for (; guards_told_ < sim_.guard_records().size(); ++guards_told_)
    say(scene_.deck_path + ": warning: " + sim_.guard_records()[guards_told_].first +
            " (run.guards = \"warn\": the run goes on)\n",
        stderr);
  const Due due = due_at(sim_.time());
  if (due.series) {
    series_.write(sim_.record_row());
    lifters_.write(sim_);
    ore_.write(sim_);
    sim_.reset_pass_window();
    watch_fill();
  }
  if (due.snapshot) snapshot();
  if (due.checkpoint) checkpoint();
}

void RunLoop::watch_fill() {
  if (fill_told_ || !scene_.feed.present || !scene_.drum.present) return;
  const ParticleStore& p = sim_.particles();
  double area = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) area += p.radius[k] * p.radius[k];
  const double r = scene_.drum.radius;
  const double j = domain_.sum(area) / (r * r) / kBedPacking;
  if (j <= kFillWarning) return;
  fill_told_ = true;
  warnings_.push_back(fmt::format(
      "at t = {:.4g} s the charge fills the drum to a bed filling of {:.3f} (above {}): the feed "
      "({}) brings in more than the discharge lets out; a lower feed rate, a wider aperture or "
      "a faster breakage keeps the mill in its range",
      sim_.time(), j, kFillWarning, scene_.feed.period > 0.0 ? "feed.period" : "feed.mass_rate"));
  say(scene_.deck_path + ": warning: " + warnings_.back() + "\n", stderr);
}

bool RunLoop::stop_requested() {
  const double minutes = scene_.output.checkpoint_minutes;
  double flags[2] = {static_cast<double>(g_stop_signal), 0.0};
  if (mpi::rank(MPI_COMM_WORLD) == 0 && minutes > 0.0 &&
      std::chrono::duration<double>(Clock::now() - last_checkpoint_).count() >= 60.0 * minutes)
    flags[1] = 1.0;
  domain_.max(flags);
  if (flags[1] > 0.0 && flags[0] == 0.0) checkpoint();
  stop_signal_ = static_cast<int>(flags[0]);
  return stop_signal_ != 0;
}

// The last state: a snapshot (unless this step's was written), the series row (not when
// interrupted: the restart writes the rows from here on, as the whole run would have), the
// logs, and the checkpoint, always.
Ending RunLoop::finish(Ending ending) {
  count_particles();
  if (last_snapshot_time_ != sim_.time()) snapshot();
  if (ending == Ending::kFinished && !due_at(sim_.time()).series) {
    series_.write(sim_.record_row());
    lifters_.write(sim_);
  }
  if (checkpoint_step_ != sim_.step_count()) checkpoint();
  return ending;
}

}  // namespace dem2d
