// dem2d: command line, wiring and exit codes (interface.md). Everything else lives in the
// libraries: the deck and outputs in src/io, the physics in src/core, MPI in src/parallel.
//
// Exit status: 0 success, 2 bad input or usage, 3 the run became unstable, 4 an I/O failure,
// 5 interrupted by SIGINT or SIGTERM (a checkpoint to resume from was written).
// Every rank parses and validates the same deck, so every rank reaches the same verdict and
// exits with the same status; rank 0 alone prints.
#include <mpi.h>
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <bit>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/simulation.hpp"
#include "io/checkpoint.hpp"
#include "io/collisions.hpp"
#include "io/deck.hpp"
#include "io/ore_logs.hpp"
#include "io/output_dir.hpp"
#include "io/run_json.hpp"
#include "io/series.hpp"
#include "io/snapshots.hpp"
#include "parallel/comm.hpp"
#include "parallel/mpi_domain.hpp"

namespace {

using namespace dem2d;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string deck;
  std::vector<std::string> sets;
  std::string output;
  std::string restart;  // a checkpoint.h5 to continue from
  bool check = false;
  bool quiet = false;
  bool overwrite = false;
};

int g_rank = 0;
int g_size = 1;

void say(const std::string& text, FILE* stream = stdout) {
  if (g_rank == 0) {
    std::fputs(text.c_str(), stream);
    std::fflush(stream);
  }
}

std::string fmt_double(const char* format, double x) {
  char buf[128];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

// The mill's numbers (--check).
std::string mill_check_lines(const Scene& s, const MillNumbers& m) {
  std::string out =
      fmt_double("  fill fraction:         %.4f (particle cross-sections / drum area)\n",
                 m.fill_fraction) +
      fmt_double("  bed filling J:         %.3f", m.bed_filling) +
      fmt_double(" (the bed with its voids / drum area, packing %.2f)\n", kBedPacking);
  out += fmt_double("  critical speed:        %.4f rad/s", m.critical_speed) +
         fmt_double(" = sqrt(g/R) (%.2f rpm);", m.critical_speed * 30.0 / std::numbers::pi) +
         fmt_double(" with fill (thesis T37) %.4f rad/s\n", m.critical_speed_with_fill);
  out += fmt_double("  drum speed:            %.4f rad/s", s.drum.speed) +
         fmt_double(" = %.3f of critical", m.speed_fraction) +
         fmt_double(" (Froude number %.4f)\n", m.froude);
  out += fmt_double("  2D to 3D:              the slice is %.4g m thick", m.slice_thickness) +
         " (the largest ball's diameter); a mill L m long draws about L / " +
         fmt_double("%.4g times its power\n", m.slice_thickness);
  return out;
}

// Derived quantities of a scene (--check).
void print_check(const Simulation& sim) {
  const Scene& s = sim.scene();
  const ParticleStore& p = sim.particles();
  const TimeScales& ts = sim.scales();
  std::string out = "dem2d --check " + s.deck_path + ": the deck is valid\n";
  if (!s.title.empty()) out += "  title:                 " + s.title + "\n";
  out += "  particles:             " + std::to_string(p.n_owned()) + "\n";
  double area = 0.0, r_max = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    area += std::numbers::pi * p.radius[k] * p.radius[k];
    r_max = std::max(r_max, p.radius[k]);
  }
  if (s.drum.present) out += mill_check_lines(s, mill_numbers(s, area, r_max));
  out += fmt_double("  Rayleigh time:         %.4e s (smallest particle)\n", ts.rayleigh);
  out += fmt_double("  Hertz contact time:    %.4e s", ts.hertz) +
         fmt_double(" at %.3f m/s (largest expected impact speed)\n", ts.impact_speed);
  out += fmt_double("  smallest restitution:  %.3f", ts.restitution_min) +
         fmt_double(" -> Hertz contact resolved with %.0f steps (1 %% restitution)\n",
                    ts.steps_per_contact);
  out += fmt_double("  safe dt:               %.4e s (dt = \"auto\")", ts.safe_dt) +
         fmt_double("; refused above %.4e s\n", ts.limit_dt);
  out += fmt_double("  chosen dt:             %.4e s", sim.dt()) +
         fmt_double(" (%.3f of the safe dt)\n", sim.dt() / ts.safe_dt);
  const double steps = std::ceil(s.run.duration / sim.dt() - 0.5);
  out += fmt_double("  steps:                 %.0f", steps) +
         fmt_double(" for %.4g s simulated\n", s.run.duration);
  const double bytes =
      static_cast<double>(p.n_owned()) * p.bytes_per_particle() +
      static_cast<double>(sim.pairs().size()) * (2 * 4 + 2 * 8 + 2 * 8 * sim.pairs().width);
  out += fmt_double("  memory estimate:       %.1f MiB\n", 2.0 * bytes / (1024.0 * 1024.0));
  out += fmt_double("  neighbour skin:        %.4g m\n", sim.skin());
  say(out);
}

class Progress {
 public:
  Progress(bool quiet, double duration, double interval, std::int64_t first_step)
      : first_step_(first_step),
        quiet_(quiet),
        tty_(isatty(STDERR_FILENO) != 0),
        duration_(duration),
        interval_(interval),
        start_(Clock::now()),
        last_(start_) {}
  void update(const Simulation& sim, std::int64_t n_particles, bool final_line = false) {
    if (quiet_ || g_rank != 0) return;
    const auto now = Clock::now();
    const double since = std::chrono::duration<double>(now - last_).count();
    if (!final_line && since < (tty_ ? 0.5 : interval_)) return;
    last_ = now;
    const double wall = std::chrono::duration<double>(now - start_).count();
    const double steps = static_cast<double>(sim.step_count() - first_step_);
    const double rate = wall > 0 ? static_cast<double>(n_particles) * steps / wall : 0;
    const double t0 = static_cast<double>(first_step_) * sim.dt();
    const double frac = (sim.time() - t0) / (duration_ - t0);
    const double eta = frac > 0 ? wall * (1.0 - frac) / frac : 0.0;
    char line[256];
    std::snprintf(line, sizeof line,
                  "step %lld  t = %.4f / %.4g s  particles %lld  %.3g particle-steps/s  ETA %.0f s",
                  static_cast<long long>(sim.step_count()), sim.time(), duration_,
                  static_cast<long long>(n_particles), rate, eta);
    if (tty_)
      std::fprintf(stderr, "\r%s\033[K%s", line, final_line ? "\n" : "");
    else
      std::fprintf(stderr, "%s\n", line);
    std::fflush(stderr);
  }

 private:
  std::int64_t first_step_;
  bool quiet_, tty_;
  double duration_, interval_;
  Clock::time_point start_, last_;
};

// Collective. An output directory that cannot be written is bad input (exit 2), named by its
// key; a write that fails later (disk full) stays an I/O failure (exit 4).
// One folder, one run: the output directory is created, checked and locked for this run (a
// folder in use, or holding another run's output without --overwrite, is bad input: exit 2).
OutputLock prepare_output(const Options& opt, const Scene& scene) {
  const std::string& dir = scene.output.directory;
  try {
    const Claim how = !opt.restart.empty() ? Claim::kContinue
                      : opt.overwrite      ? Claim::kOverwrite
                                           : Claim::kNew;
    return claim_output_directory(MPI_COMM_WORLD, dir, how);
  } catch (const IoError& e) {
    const auto at = scene.where.find("output.directory");  // its line, or the --set
    const std::string deck_at = at != scene.where.end() ? at->second : scene.deck_path;
    const std::string source = opt.output.empty()
                                   ? deck_at + ": error: output.directory = '" + dir + "': "
                                   : "--output " + opt.output + ": error: ";
    throw InputError(source + e.what());
  }
}

// series.csv: rank 0 alone writes it; every write is agreed on, so a failure there (disk full)
// stops every rank with the same message instead of leaving the others in a collective.
class SeriesOutput {
 public:
  // `resumed`: a restart, which continues the file after the checkpoint's step.
  SeriesOutput(const Scene& scene, const Simulation& sim, bool resumed) {
    std::string error;
    try {
      file_ = std::make_unique<SeriesWriter>(scene.output.directory + "/" + kSeriesFile,
                                             scene.run.integrator == IntegratorKind::kIterative,
                                             g_rank == 0, is_ore_scene(scene),
                                             resumed ? sim.step_count() : -1, scene.drum.present);
    } catch (const IoError& e) {
      error = e.what();
    }
    mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
  }
  void write(const SeriesRow& row) {
    std::string error;
    try {
      file_->write(row);
    } catch (const IoError& e) {
      error = e.what();
    }
    mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
  }

 private:
  std::unique_ptr<SeriesWriter> file_;
};

// product.csv and breakages.csv of ore scenes: every rank's records since the last row are
// gathered (as 64-bit words) and rank 0 appends them; a write failure stops every rank alike.
class OreOutput {
 public:
  OreOutput(const Scene& scene, const Simulation& sim, bool resumed) {
    if (!is_ore_scene(scene)) return;
    std::string error;
    try {
      logs_ = std::make_unique<OreLogs>(scene.output.directory, g_rank == 0,
                                        resumed ? sim.time() : -1.0);
    } catch (const IoError& e) {
      error = e.what();
    }
    mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
  }
  void write(Simulation& sim) {
    if (!logs_) return;
    std::vector<std::int64_t> words;
    const auto put = [&words](auto x) {
      if constexpr (std::is_same_v<decltype(x), double>)
        words.push_back(std::bit_cast<std::int64_t>(x));
      else
        words.push_back(static_cast<std::int64_t>(x));
    };
    const std::vector<BreakageRecord> mine_b = sim.grinding()->take_breakages();
    const std::vector<ProductRecord> mine_p = sim.grinding()->take_product();
    put(mine_b.size());
    for (const BreakageRecord& r : mine_b) {
      put(r.time), put(r.parent), put(r.radius), put(r.energy), put(r.fragments), put(r.first_id);
    }
    for (const ProductRecord& r : mine_p) put(r.time), put(r.id), put(r.radius), put(r.mass);
    put(mine_p.size());  // last: the reader walks each rank's block from both ends
    words.insert(words.begin(), static_cast<std::int64_t>(words.size()) + 1);
    const std::vector<std::int64_t> all = mpi::all_gather(MPI_COMM_WORLD, words);
    std::vector<BreakageRecord> breakages;
    std::vector<ProductRecord> product;
    const auto real = [](std::int64_t w) { return std::bit_cast<double>(w); };
    for (std::size_t at = 0; at < all.size(); at += static_cast<std::size_t>(all[at])) {
      const std::int64_t* w = &all[at + 1];
      const std::int64_t nb = *w++;
      for (std::int64_t k = 0; k < nb; ++k, w += 6)
        breakages.push_back(
            {real(w[0]), w[1], real(w[2]), real(w[3]), static_cast<int>(w[4]), w[5]});
      const std::size_t end = at + static_cast<std::size_t>(all[at]);
      const std::int64_t np = all[end - 1];
      for (std::int64_t k = 0; k < np; ++k, w += 4)
        product.push_back({real(w[0]), w[1], real(w[2]), real(w[3])});
    }
    std::string error;
    try {
      logs_->write(std::move(breakages), std::move(product));
    } catch (const IoError& e) {
      error = e.what();
    }
    mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
  }

 private:
  std::unique_ptr<OreLogs> logs_;
};

// SIGINT and SIGTERM (mpirun passes SIGTERM on to every rank) ask the run to stop. The flag
// is read every kStopPollSteps steps in one reduction, so every rank stops after the same
// step; the run then writes its checkpoint, last snapshot and run.json and exits with
// kExitInterrupted. The handler resets itself: a second signal ends the process at once (the
// checkpoint on disk is then the previous one, whole).
volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void on_stop_signal(int signo) { g_stop_signal = signo; }
void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}
constexpr std::int64_t kStopPollSteps = 100;

enum class Ending { kFinished, kUnstable, kInterrupted };

// The time loop with its outputs: series rows, snapshots and checkpoints at their intervals,
// the first state (not on a restart: the interrupted run wrote it) and the last one always.
class RunLoop {
 public:
  RunLoop(Simulation& sim, const Scene& scene, Domain& domain, SeriesOutput& series,
          SnapshotWriter& snapshots, bool resumed)
      : sim_(sim),
        scene_(scene),
        domain_(domain),
        series_(series),
        snapshots_(snapshots),
        ore_(scene, sim, resumed),
        resumed_(resumed),
        last_checkpoint_(Clock::now()) {}
  Ending run(Progress& progress, std::int64_t n_global);
  // The signal that stopped the run (kInterrupted).
  int stop_signal() const { return stop_signal_; }

 private:
  bool at_multiple(double t, double interval) const {
    if (interval <= 0.0) return false;
    const double k = std::round(t / interval);
    return std::abs(t - k * interval) < 0.5 * sim_.dt();
  }
  void snapshot() {
    snapshots_.write(sim_.particles(), sim_.time(), sim_.step_count(), wall_outlines(sim_.walls()));
    last_snapshot_time_ = sim_.time();
    if (sim_.spectra()) write_collisions(MPI_COMM_WORLD, scene_.output.directory, *sim_.spectra());
  }
  // The outputs due at time t: one test for the step that acts on them (after_step, finish)
  // and for the one that predicts them (observes_next_step).
  struct Due {
    bool series, snapshot, checkpoint;
    bool any() const { return series || snapshot || checkpoint; }
  };
  Due due_at(double t) const {
    const OutputSpec& out = scene_.output;
    return {at_multiple(t, out.series_interval), at_multiple(t, out.snapshot_interval),
            at_multiple(t, out.checkpoint_interval)};
  }
  static bool polls_at(std::int64_t step) { return step % kStopPollSteps == 0; }
  void after_step();
  // Whether anything reads the particles after the coming step: an output or checkpoint due at
  // its time, the stop poll, the end of the run (else the step may run ahead: Simulation::step).
  bool observes_step(std::int64_t next) const {
    const double t = static_cast<double>(next) * sim_.dt();  // Simulation::advance_clock's
    return polls_at(next) || t + 0.5 * sim_.dt() >= scene_.run.duration || due_at(t).any();
  }
  // The logs' records up to now first: a restart keeps the rows up to the checkpoint's time.
  void checkpoint() {
    ore_.write(sim_);
    write_checkpoint(MPI_COMM_WORLD, scene_.output.directory + "/" + kCheckpointFile, sim_);
    last_checkpoint_ = Clock::now();
    checkpoint_step_ = sim_.step_count();
  }
  // The poll: a stop signal on any rank, and rank 0's clock for output.checkpoint_minutes.
  bool stop_requested();
  Ending finish(Ending ending);

  Simulation& sim_;
  const Scene& scene_;
  Domain& domain_;
  SeriesOutput& series_;
  SnapshotWriter& snapshots_;
  OreOutput ore_;
  bool resumed_;
  Clock::time_point last_checkpoint_;
  double last_snapshot_time_ = -1.0;
  std::int64_t checkpoint_step_ = -1;  // the step of the last checkpoint written
  std::size_t guards_told_ = 0;        // run.guards = "warn": each kind is told when it first fires
  int stop_signal_ = 0;
};

Ending RunLoop::run(Progress& progress, std::int64_t n_global) {
  const OutputSpec& out = scene_.output;
  if (!resumed_) {
    series_.write(sim_.record_row());
    sim_.reset_pass_window();
    if (out.snapshot_interval > 0) snapshot();
  }
  try {
    while (sim_.time() + 0.5 * sim_.dt() < scene_.run.duration) {
      sim_.step(observes_step(sim_.step_count() + 1));
      after_step();
      if (polls_at(sim_.step_count()) && stop_requested()) return finish(Ending::kInterrupted);
      progress.update(sim_, n_global);
    }
  } catch (const UnstableError& e) {
    ore_.write(sim_);
    snapshots_.write(sim_.particles(), sim_.time(), sim_.step_count(), wall_outlines(sim_.walls()));
    say(scene_.deck_path + ": error: " + e.what() + "; last snapshot written to " + out.directory +
            "/" + kSnapshotsFile + "\n",
        stderr);
    return Ending::kUnstable;
  }
  progress.update(sim_, n_global, true);
  return finish(Ending::kFinished);
}

void RunLoop::after_step() {
  for (; guards_told_ < sim_.guard_records().size(); ++guards_told_)
    say(scene_.deck_path + ": warning: " + sim_.guard_records()[guards_told_].first +
            " (run.guards = \"warn\": the run goes on)\n",
        stderr);
  const Due due = due_at(sim_.time());
  if (due.series) {
    series_.write(sim_.record_row());
    ore_.write(sim_);
    sim_.reset_pass_window();
  }
  if (due.snapshot) snapshot();
  if (due.checkpoint) checkpoint();
}

bool RunLoop::stop_requested() {
  const double minutes = scene_.output.checkpoint_minutes;
  double flags[2] = {static_cast<double>(g_stop_signal), 0.0};
  if (g_rank == 0 && minutes > 0.0 &&
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
  if (last_snapshot_time_ != sim_.time()) snapshot();
  if (ending == Ending::kFinished && !due_at(sim_.time()).series) series_.write(sim_.record_row());
  if (checkpoint_step_ != sim_.step_count()) checkpoint();
  return ending;
}

// Collective: run.json's "mill" object: the mill's numbers, and the averages and regime over
// the last analysis window.
std::string mill_json(const Simulation& sim, const MpiDomain& domain) {
  const ParticleStore& p = sim.particles();
  double area = 0.0, r_max = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    area += std::numbers::pi * p.radius[k] * p.radius[k];
    r_max = std::max(r_max, p.radius[k]);
  }
  const MillNumbers m = mill_numbers(sim.scene(), domain.sum(area), domain.max(r_max));
  const WindowSummary w = sim.mill_summary();
  const auto number = [](double x) { return std::isfinite(x) ? fmt_double("%.10g", x) : "null"; };
  const std::pair<const char*, double> items[] = {
      {"critical_speed_rad_s", m.critical_speed},
      {"critical_speed_rpm", m.critical_speed * 30.0 / std::numbers::pi},
      {"critical_speed_with_fill_rad_s", m.critical_speed_with_fill},
      {"speed_fraction_of_critical", m.speed_fraction},
      {"froude_number", m.froude},
      {"fill_fraction", m.fill_fraction},
      {"bed_filling", m.bed_filling},
      {"bed_packing", kBedPacking},
      {"slice_thickness_m", m.slice_thickness},
      {"window_s", w.span},
      {"power_avg_W", w.power},
      {"power_per_metre_W", m.slice_thickness > 0 ? w.power / m.slice_thickness : 0.0},
      {"airborne_fraction", w.airborne},
      {"corotating_fraction", w.corotating},
      {"toe_angle_deg", w.toe},
      {"shoulder_angle_deg", w.shoulder},
      {"surface_angle_deg", w.surface_angle},
      {"charge_angle_deg", w.charge_angle},
      {"charge_angle_std_deg", w.charge_angle_std}};
  std::string out = "{\"regime\": \"" + std::string(regime_name(w.regime)) + "\"";
  for (const auto& [key, value] : items) out += ", \"" + std::string(key) + "\": " + number(value);
  return out + "}";
}

// Collective (the decomposition's per-rank figures are gathered): what run.json records.
// `steps_here`: the steps this process took (a restart continues the step count).
RunInfo run_info(const Simulation& sim, const MpiDomain& domain, const Scene& scene,
                 std::int64_t n_global, double wall, std::int64_t steps_here) {
  RunInfo info;
  info.version = DEM2D_VERSION;
  info.ranks = g_size;
  info.wall_time_s = wall;
  info.steps = sim.step_count();
  info.particle_steps_per_second =
      wall > 0 ? static_cast<double>(n_global) * static_cast<double>(steps_here) / wall : 0.0;
  info.dt = sim.dt();
  info.extra.emplace_back("neighbor_builds", std::to_string(sim.neighbor_builds()));
  if (scene.run.integrator == IntegratorKind::kIterative) {
    info.extra.emplace_back("mean_passes",
                            fmt_double("%.6g", static_cast<double>(sim.passes_total()) /
                                                   std::max<std::int64_t>(1, sim.step_count())));
    info.extra.emplace_back("unconverged_steps", std::to_string(sim.unconverged_steps()));
  }
  std::string guards = "{";
  for (const GuardRecord& g : sim.guard_records())
    guards += (guards.size() > 1 ? ", \"" : "\"") + g.kind + "\": " + std::to_string(g.count);
  info.extra.emplace_back("guards_fired", guards + "}");
  // The decomposition: per-rank work (owned particles + listed pairs at the last rebuild),
  // ghosts, migrations and time in communication; the imbalance against equal angles.
  const DecompositionStats& ds = domain.stats();
  const RankStats per_rank = domain.gather_rank_stats();
  const auto list = [](const std::vector<double>& v, const char* fmt) {
    std::string out = "[";
    for (std::size_t k = 0; k < v.size(); ++k) out += (k ? ", " : "") + fmt_double(fmt, v[k]);
    return out + "]";
  };
  info.extra.emplace_back("rank_work", list(per_rank.work, "%.0f"));
  info.extra.emplace_back("rank_ghosts", list(per_rank.ghosts, "%.0f"));
  info.extra.emplace_back("rank_comm_seconds", list(per_rank.comm_seconds, "%.4g"));
  info.extra.emplace_back("imbalance", fmt_double("%.4g", ds.imbalance_work));
  info.extra.emplace_back("imbalance_mean", fmt_double("%.4g", ds.imbalance_mean()));
  info.extra.emplace_back("imbalance_equal_angle", fmt_double("%.4g", ds.imbalance_equal_angle));
  info.extra.emplace_back("partitions", std::to_string(ds.partitions));
  info.extra.emplace_back("partition_method", "\"" + ds.method + "\"");
  info.extra.emplace_back("sectors", std::to_string(domain.partition().n_sectors));
  if (scene.drum.present) info.extra.emplace_back("mill", mill_json(sim, domain));
  return info;
}

// The simulation: a new run, or --restart's checkpoint continued (every rank reads it).
std::unique_ptr<Simulation> make_simulation(const Options& opt, const Scene& scene,
                                            MpiDomain& domain) {
  if (opt.restart.empty()) return std::make_unique<Simulation>(scene, &domain);
  const Resumption r = read_checkpoint(MPI_COMM_WORLD, opt.restart, scene);
  if (r.state.time + 0.5 * r.state.dt >= scene.run.duration)
    throw InputError(scene.deck_path + ": error: --restart " + opt.restart +
                     fmt_double(": the checkpoint is at t = %.10g s,", r.state.time) +
                     fmt_double(" at or past run.duration = %.10g s: nothing to run; give a "
                                "longer duration, e.g. --set run.duration=...",
                                scene.run.duration));
  try {
    return std::make_unique<Simulation>(scene, &domain, &r);
  } catch (const InputError& e) {  // the checkpoint does not fit this deck
    throw InputError(scene.deck_path + ": error: --restart " + opt.restart + ": " + e.what());
  }
}

std::unique_ptr<SnapshotWriter> open_snapshots(const Scene& scene, const Simulation& sim,
                                               bool resumed) {
  const OutputSpec& out = scene.output;
  if (!resumed)
    return std::make_unique<SnapshotWriter>(MPI_COMM_WORLD, out.directory, scene.materials);
  return SnapshotWriter::resume(MPI_COMM_WORLD, out.directory, scene.materials, sim.time(),
                                0.5 * sim.dt());
}

// The command that continues an interrupted run.
std::string resume_command(const Options& opt, const Scene& scene) {
  std::string cmd = g_size > 1 ? "mpirun -np " + std::to_string(g_size) + " dem2d" : "dem2d";
  cmd += " --restart " + scene.output.directory + "/" + kCheckpointFile;
  for (const std::string& set : opt.sets) cmd += " --set " + set;
  if (!opt.output.empty()) cmd += " --output " + opt.output;
  if (opt.quiet) cmd += " --quiet";
  return cmd + " " + opt.deck;
}

// What the end of a run says, and its exit status.
int report(const Options& opt, const Scene& scene, const Simulation& sim, const RunLoop& loop,
           Ending ending) {
  if (ending == Ending::kInterrupted) {
    say(scene.deck_path + ": " + (loop.stop_signal() == SIGINT ? "SIGINT" : "SIGTERM") +
            fmt_double(": the run stopped at t = %.6g s", sim.time()) + " (step " +
            std::to_string(sim.step_count()) + "); checkpoint, last snapshot and run.json " +
            "written to " + scene.output.directory + "; resume with:\n  " +
            resume_command(opt, scene) + "\n",
        stderr);
    return kExitInterrupted;
  }
  if (sim.unconverged_steps() > 0)
    say("warning: the iterative integrator did not converge in " +
            std::to_string(sim.unconverged_steps()) +
            " steps (run.max_passes = " + std::to_string(scene.run.max_passes) + ")\n",
        stderr);
  if (sim.guard_records().empty()) return kExitOk;
  for (const GuardRecord& g : sim.guard_records())
    say(scene.deck_path + ": error: the " + g.kind + " guard fired " + std::to_string(g.count) +
            (g.count == 1 ? " time" : " times") + " (first: " + g.first + ")\n",
        stderr);
  return kExitUnstable;  // the run went to its end (run.guards = "warn"), but it is not sane
}

int run(const Options& opt) {
  Scene scene = load_deck(opt.deck, opt.sets);
  if (!opt.output.empty()) scene.output.directory = opt.output;
  if (opt.check) {
    // Every rank evaluates the whole scene alike; rank 0 prints.
    const Simulation whole(scene);
    print_check(whole);
    return kExitOk;
  }
  MpiDomain domain(MPI_COMM_WORLD, decomposition_of(scene));
  const bool resumed = !opt.restart.empty();
  const std::unique_ptr<Simulation> owned_sim = make_simulation(opt, scene, domain);
  Simulation& sim = *owned_sim;
  const std::int64_t n_global = domain.sum(static_cast<std::int64_t>(sim.particles().n_owned()));
  const OutputSpec& out = scene.output;
  const OutputLock lock = prepare_output(opt, scene);
  SeriesOutput series(scene, sim, resumed);
  const std::unique_ptr<SnapshotWriter> snapshots = open_snapshots(scene, sim, resumed);
  if (!opt.quiet)
    say("dem2d " DEM2D_VERSION ": " + scene.deck_path + " (" + std::to_string(n_global) +
        " particles, dt = " + fmt_double("%.4g s", sim.dt()) + ", " + std::to_string(g_size) +
        (g_size == 1 ? " rank" : " ranks") + ") -> " + out.directory +
        (resumed ? fmt_double(", continued from t = %.6g s", sim.time()) : "") + "\n");

  Progress progress(opt.quiet, scene.run.duration, out.progress_interval, sim.step_count());
  const auto start = Clock::now();
  const std::int64_t first_step = sim.step_count();
  RunLoop loop(sim, scene, domain, series, *snapshots, resumed);
  const Ending ending = loop.run(progress, n_global);
  if (ending == Ending::kUnstable) return kExitUnstable;
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  RunInfo info = run_info(sim, domain, scene, n_global, wall, sim.step_count() - first_step);
  info.extra.emplace_back("interrupted", ending == Ending::kInterrupted ? "true" : "false");
  info.extra.emplace_back("restarted_from", resumed ? "\"" + opt.restart + "\"" : "null");
  if (g_rank == 0) write_run_json(out.directory + "/" + kRunJsonFile, scene, info);
  if (!opt.quiet && ending == Ending::kFinished)
    say(fmt_double("done: %.4g s simulated", sim.time()) +
        fmt_double(" in %.3g s of wall time", wall) +
        fmt_double(" (%.3g particle-steps/s)\n", info.particle_steps_per_second));
  return report(opt, scene, sim, loop, ending);
}

}  // namespace

int main(int argc, char** argv) {
  mpi::init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  install_stop_handlers();

  CLI::App app{"dem2d: 2D discrete element simulator of tumbling ball mills", "dem2d"};
  // The usage line names every option in the order given below (CLI11 prints "[OPTIONS]").
  struct UsageFormatter : CLI::Formatter {
    std::string make_usage(const CLI::App* a, std::string name) const override {
      std::string out = "Usage: " + name, positionals;
      for (const CLI::Option* o : a->get_options()) {
        std::string arg = o->get_type_name().empty() ? "" : " " + o->get_type_name();
        if (o->get_expected_max() > 1) arg += " ...";
        if (o->get_positional()) {
          positionals += " " + o->get_name();
        } else if (!o->get_name().empty()) {  // not hidden
          out += " [" + o->get_name() + arg + "]";
        }
      }
      return out + positionals + "\n";
    }
  };
  app.formatter(std::make_shared<UsageFormatter>());
  Options opt;
  app.add_option("INPUT", opt.deck, "input deck (.in, TOML)");
  app.add_flag("--check", opt.check, "validate the deck, print derived quantities, run nothing");
  // One KEY=VALUE per --set (repeatable), so that --set may stand before the deck too.
  app.add_option("--set", opt.sets, "override a deck key: --set drum.speed=1.5 (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  app.add_option("--output", opt.output, "output directory (overrides output.directory)")
      ->type_name("DIR");
  app.add_option("--restart", opt.restart,
                 "continue the run from a checkpoint (DIR/checkpoint.h5) to the deck's "
                 "run.duration, on any rank count, appending to the output in the deck's folder")
      ->type_name("FILE");
  app.add_flag("--quiet", opt.quiet, "no progress line");
  app.add_flag("--overwrite", opt.overwrite,
               "replace the output of an earlier run in the output directory (never a running "
               "one's)");
  bool version = false;
  app.add_flag("--version", version, "print the version and exit");

  int code = kExitOk;
  try {
    app.parse(argc, argv);
    if (version) {
      say("dem2d " DEM2D_VERSION "\n");
    } else if (!opt.restart.empty() && opt.overwrite) {
      say("dem2d: error: --restart continues the output in its folder; --overwrite would remove "
          "it: give one of them\n",
          stderr);
      code = kExitInput;
    } else if (opt.deck.empty()) {
      say("dem2d: error: no input deck given\nRun with --help for more information.\n", stderr);
      code = kExitInput;
    } else {
      code = run(opt);
    }
  } catch (const CLI::ParseError& e) {
    if (g_rank == 0) code = app.exit(e);
    code = e.get_exit_code() == 0 ? kExitOk : kExitInput;
  } catch (const InputError& e) {
    for (const std::string& m : e.messages()) say(m + "\n", stderr);
    code = kExitInput;
  } catch (const IoError& e) {
    say(std::string("dem2d: error: ") + e.what() + "\n", stderr);
    code = kExitIo;
  } catch (const std::exception& e) {
    say(std::string("dem2d: internal error: ") + e.what() + "\n", stderr);
    code = 1;
  }
  MPI_Finalize();
  return code;
}
