// dem2d: command line, wiring and exit codes (interface.md). Everything else lives in the
// libraries: the deck and outputs in src/io, the physics in src/core, MPI in src/parallel.
//
// Exit status: 0 success, 2 bad input or usage, 3 the run became unstable, 4 an I/O failure.
// Every rank parses and validates the same deck, so every rank reaches the same verdict and
// exits with the same status; rank 0 alone prints.
#include <mpi.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/simulation.hpp"
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

// Derived quantities of a scene (--check).
void print_check(const Simulation& sim) {
  const Scene& s = sim.scene();
  const ParticleStore& p = sim.particles();
  const TimeScales& ts = sim.scales();
  std::string out = "dem2d --check " + s.deck_path + ": the deck is valid\n";
  if (!s.title.empty()) out += "  title:                 " + s.title + "\n";
  out += "  particles:             " + std::to_string(p.n_owned()) + "\n";
  double area = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    area += std::numbers::pi * p.radius[k] * p.radius[k];
  const double g = norm(s.run.gravity);
  if (s.drum.present) {
    const double R = s.drum.radius;
    const double phi = area / (std::numbers::pi * R * R);
    const double w_classic = std::sqrt(g / R);
    const double w_thesis = std::pow(1.0 - std::min(phi, 0.99), -0.25) * w_classic;  // T37
    out += fmt_double("  fill fraction:         %.4f (particle cross-sections / drum area)\n", phi);
    out += fmt_double("  critical speed:        %.4f rad/s", w_classic) +
           fmt_double(" = sqrt(g/R) (%.2f rpm);", w_classic * 30.0 / std::numbers::pi) +
           fmt_double(" with fill (thesis T37) %.4f rad/s\n", w_thesis);
    out += fmt_double("  drum speed:            %.4f rad/s", s.drum.speed) +
           fmt_double(" = %.3f of critical", s.drum.speed / w_classic) +
           fmt_double(" (Froude number %.4f)\n", s.drum.speed * s.drum.speed * R / g);
  }
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
  Progress(bool quiet, double duration, double interval)
      : quiet_(quiet),
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
    const double rate = wall > 0 ? static_cast<double>(n_particles) * sim.step_count() / wall : 0;
    const double frac = sim.time() / duration_;
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
  bool quiet_, tty_;
  double duration_, interval_;
  Clock::time_point start_, last_;
};

// The angular-sector decomposition about the drum centre (the particles' centre without a
// drum); on one rank its verbs are trivial.
DecompositionOptions decomposition_of(const Scene& scene) {
  DecompositionOptions d;
  d.has_center = scene.drum.present;
  d.center = scene.drum.center;
  d.sectors_per_rank = scene.run.sectors_per_rank;
  d.repartition_threshold = scene.run.repartition_threshold;
  return d;
}

// Collective. An output directory that cannot be written is bad input (exit 2), named by its
// key; a write that fails later (disk full) stays an I/O failure (exit 4).
// One folder, one run: the output directory is created, checked and locked for this run (a
// folder in use, or holding another run's output without --overwrite, is bad input: exit 2).
OutputLock prepare_output(const Options& opt, const Scene& scene) {
  const std::string& dir = scene.output.directory;
  try {
    return claim_output_directory(MPI_COMM_WORLD, dir, opt.overwrite);
  } catch (const IoError& e) {
    const std::string source = opt.output.empty()
                                   ? scene.deck_path + ": error: output.directory = '" + dir + "': "
                                   : "--output " + opt.output + ": error: ";
    throw InputError(source + e.what());
  }
}

// series.csv: rank 0 alone writes it; every write is agreed on, so a failure there (disk full)
// stops every rank with the same message instead of leaving the others in a collective.
class SeriesOutput {
 public:
  explicit SeriesOutput(const Scene& scene) {
    std::string error;
    try {
      file_ = std::make_unique<SeriesWriter>(scene.output.directory + "/" + kSeriesFile,
                                             scene.run.integrator == IntegratorKind::kIterative,
                                             g_rank == 0, is_ore_scene(scene));
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
  explicit OreOutput(const Scene& scene) {
    if (!is_ore_scene(scene)) return;
    std::string error;
    try {
      logs_ = std::make_unique<OreLogs>(scene.output.directory, g_rank == 0);
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

// The time loop with its outputs: series rows and snapshots at their intervals, the first and
// last state always. Returns false when the run became unstable, after writing a last
// snapshot and reporting it.
bool advance(Simulation& sim, const Scene& scene, SeriesOutput& series, SnapshotWriter& snapshots,
             Progress& progress, std::int64_t n_global) {
  OreOutput ore(scene);
  const OutputSpec& out = scene.output;
  const double dt = sim.dt();
  const auto at_multiple = [dt](double t, double interval) {
    if (interval <= 0.0) return false;
    const double k = std::round(t / interval);
    return std::abs(t - k * interval) < 0.5 * dt;
  };
  double last_snapshot_time = -1.0;
  const auto snapshot = [&] {
    snapshots.write(sim.particles(), sim.time(), sim.step_count());
    last_snapshot_time = sim.time();
  };
  series.write(sim.diagnostics());
  sim.reset_pass_window();
  if (out.snapshot_interval > 0) snapshot();
  std::size_t guards_told = 0;  // run.guards = "warn": each kind is told when it first fires
  try {
    while (sim.time() + 0.5 * dt < scene.run.duration) {
      sim.step();
      for (; guards_told < sim.guard_records().size(); ++guards_told)
        say(scene.deck_path + ": warning: " + sim.guard_records()[guards_told].first +
                " (run.guards = \"warn\": the run goes on)\n",
            stderr);
      if (at_multiple(sim.time(), out.series_interval)) {
        series.write(sim.diagnostics());
        ore.write(sim);
        sim.reset_pass_window();
      }
      if (at_multiple(sim.time(), out.snapshot_interval)) snapshot();
      progress.update(sim, n_global);
    }
  } catch (const UnstableError& e) {
    ore.write(sim);
    snapshots.write(sim.particles(), sim.time(), sim.step_count());
    say(scene.deck_path + ": error: " + e.what() + "; last snapshot written to " + out.directory +
            "/snapshots.h5\n",
        stderr);
    return false;
  }
  if (last_snapshot_time != sim.time()) snapshot();
  if (!at_multiple(sim.time(), out.series_interval)) series.write(sim.diagnostics());
  ore.write(sim);
  progress.update(sim, n_global, true);
  return true;
}

// Collective (the decomposition's per-rank figures are gathered): what run.json records.
RunInfo run_info(const Simulation& sim, const MpiDomain& domain, const Scene& scene,
                 std::int64_t n_global, double wall) {
  RunInfo info;
  info.version = DEM2D_VERSION;
  info.ranks = g_size;
  info.wall_time_s = wall;
  info.steps = sim.step_count();
  info.particle_steps_per_second =
      wall > 0 ? static_cast<double>(n_global) * sim.step_count() / wall : 0.0;
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
  return info;
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
  Simulation sim(scene, &domain);
  const std::int64_t n_global = domain.sum(static_cast<std::int64_t>(sim.particles().n_owned()));
  const OutputSpec& out = scene.output;
  const OutputLock lock = prepare_output(opt, scene);
  SeriesOutput series(scene);
  SnapshotWriter snapshots(MPI_COMM_WORLD, out.directory, scene.materials);
  if (!opt.quiet)
    say("dem2d " DEM2D_VERSION ": " + scene.deck_path + " (" + std::to_string(n_global) +
        " particles, dt = " + fmt_double("%.4g s", sim.dt()) + ", " + std::to_string(g_size) +
        (g_size == 1 ? " rank" : " ranks") + ") -> " + out.directory + "\n");

  Progress progress(opt.quiet, scene.run.duration, out.progress_interval);
  const auto start = Clock::now();
  if (!advance(sim, scene, series, snapshots, progress, n_global)) return kExitUnstable;
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const RunInfo info = run_info(sim, domain, scene, n_global, wall);
  if (g_rank == 0) write_run_json(out.directory + "/" + kRunJsonFile, scene, info);
  if (!opt.quiet)
    say(fmt_double("done: %.4g s simulated", sim.time()) +
        fmt_double(" in %.3g s of wall time", wall) +
        fmt_double(" (%.3g particle-steps/s)\n", info.particle_steps_per_second));
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

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);

  CLI::App app{"dem2d: 2D discrete element simulator of tumbling ball mills"};
  Options opt;
  app.add_option("INPUT", opt.deck, "input deck (.in, TOML)");
  app.add_flag("--check", opt.check, "validate the deck, print derived quantities, run nothing");
  // One KEY=VALUE per --set (repeatable), so that --set may stand before the deck too.
  app.add_option("--set", opt.sets, "override a deck key: --set drum.speed=1.5 (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--output", opt.output, "output directory (overrides output.directory)");
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
