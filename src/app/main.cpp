// dem2d: command line, wiring and exit codes (docs/architecture.md, "Command line and exit
// status"). Everything else lives in the libraries: the deck and outputs in src/io, the physics in
// src/core, MPI in src/parallel.
//
// Exit status: 0 success, 2 bad input or usage, 3 the run became unstable, 4 an I/O failure,
// 5 interrupted by SIGINT or SIGTERM (a checkpoint to resume from was written).
// Every rank parses and validates the same deck, so every rank reaches the same verdict and
// exits with the same status; rank 0 alone prints.
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "core/run/simulation.hpp"
#include "core/setup/validate.hpp"
#include "io/check_report.hpp"
#include "io/checkpoint.hpp"
#include "io/console.hpp"
#include "io/deck.hpp"
#include "io/grinding_report.hpp"
#include "io/output_dir.hpp"
#include "io/run_info.hpp"
#include "io/run_json.hpp"
#include "io/run_loop.hpp"
#include "io/run_outputs.hpp"
#include "io/snapshots.hpp"
#include "io/text.hpp"
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

// Collective. An output directory that cannot be written is bad input (exit 2), named by its
// key; a write that fails later (disk full) stays an I/O failure (exit 4).
// One folder, one run: the output directory is created, checked and locked for this run (a
// folder in use, holding another run's output without --overwrite, or, for --restart, holding
// the output of another run than the checkpoint's, is bad input: exit 2).
OutputLock prepare_output(const Options& opt, const Scene& scene) {
  const std::string& dir = scene.output.directory;
  try {
    const Claim how = !opt.restart.empty() ? Claim::kContinue
                      : opt.overwrite      ? Claim::kOverwrite
                                           : Claim::kNew;
    if (how == Claim::kContinue) check_restart_folder(MPI_COMM_WORLD, dir, opt.restart, scene);
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

// Output intervals shorter than a step are written every step; the deck is told so.
void tell_interval_notes(const Scene& scene, double dt) {
  for (const std::string& note : output_interval_notes(scene, dt)) say(note + "\n", stderr);
}

int run(const Options& opt) {
  Scene scene = load_deck(opt.deck, opt.sets);
  if (!opt.output.empty()) scene.output.directory = opt.output;
  if (opt.check) {
    // Every rank evaluates the whole scene alike; rank 0 prints.
    const Simulation whole(scene);
    tell_interval_notes(scene, whole.dt());
    say(check_report(whole, timed_trial(scene)));
    return kExitOk;
  }
  MpiDomain domain(MPI_COMM_WORLD, decomposition_of(scene));
  const bool resumed = !opt.restart.empty();
  const std::unique_ptr<Simulation> owned_sim = make_simulation(opt, scene, domain);
  Simulation& sim = *owned_sim;
  tell_interval_notes(scene, sim.dt());
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
  // A [sieve] without `type` may have been written when the aperture was compared with the
  // radius: the run says how it reads it.
  if (scene.sieve.present && !scene.where.contains("sieve.type"))
    say(scene.deck_path + fmt_double(": note: sieve.aperture = %g m is a diameter: ore narrower "
                                     "than it leaves (a deck that meant a radius gives twice "
                                     "the value)\n",
                                     scene.sieve.aperture));
  if (is_ore_scene(scene) && !scene.sieve.present)
    say(scene.deck_path + ": note: no [sieve]: nothing leaves the mill, " + kProductFile +
        " keeps only its header\n");

  Progress progress(opt.quiet, scene.run.duration, out.progress_interval, sim.step_count());
  const auto start = Clock::now();
  const std::int64_t first_step = sim.step_count();
  RunLoop loop(sim, scene, domain, series, *snapshots, resumed);
  const Ending ending = loop.run(progress);
  snapshots->close();  // synced to disk (docs/output.md, "Crash safety")
  if (ending == Ending::kUnstable) return kExitUnstable;
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const RunInfo info = run_info(
      sim, domain, scene,
      {n_global, loop.particles(), loop.particle_steps(), wall, sim.step_count() - first_step,
       ending == Ending::kInterrupted, opt.restart, opt.sets, loop.warnings(), &loop.lifters()});
  if (g_rank == 0) write_run_json(out.directory + "/" + kRunJsonFile, scene, info);
  if (is_ore_scene(scene)) {
    const GrindingReport sizes = grinding_report(sim, domain);
    std::string error;
    try {
      if (g_rank == 0) write_sizes_csv(out.directory, sizes);
    } catch (const IoError& e) {
      error = e.what();
    }
    mpi::agree_on_failure<IoError>(MPI_COMM_WORLD, error);
  }
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
