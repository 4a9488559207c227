// strong_scaling: the same scenes at 1 and 2 ranks.
//
//   build/bench/strong_scaling [--ranks 1,2] [--particles N1,N2,...] [--steps S] [--repeats R]
//                              [--waterfall-time T] [--no-waterfall] [--no-plot] [--results DIR]
//                              [--csv NAME]
//
// Run without --worker, the program starts itself under `mpirun -np P --worker` for each P and
// collects one CSV row per (scene, P) from each worker; it then prints the table (speedup and
// efficiency against P = 1), writes DIR/strong_scaling.csv and plots DIR/strong_scaling.png
// with post/plot_strong_scaling.py.
//
// Scenes:
//  - drum<N/1000>k for each N of --particles (default 30000: drum30k): the settled charge of
//    bench/throughput (bench/settled_drum.hpp; N >= 300 000 the deposited bed, in the material
//    it is loaded in), read from DIR/cache/settled_drum_<N>.csv or deposited_drum_<N>.csv
//    (never made here: run build/bench/throughput --sections drum --particles N, or
//    --sections deposited --deposited N, once; a missing packing is reported and skipped),
//    drum at full speed, dt 1e-6 s; 300 untimed steps, then S timed steps
//    (default 2000) for N <= 30 000, max(50, S 30 000 / N) above (600 at 1e5, 60 at 1e6).
//  - waterfall: inputs/waterfall_polygon.in (240 balls), T simulated seconds (default 1);
//    --no-waterfall leaves it out.
// Each timed segment runs R times in a row (--repeats, default 3); the fastest counts, and the
// slowest is reported too (wall_max, the spread on a shared machine), with the CPU time of the
// fastest (cpu: the largest over the ranks; on an oversubscribed machine it leaves out the
// time a rank was preempted, but includes MPI's busy waiting for the other rank).
// Columns: wall (max over ranks of the timed loop), speedup and efficiency, imbalance (max/mean of
// the ranks' work = owned particles + listed pairs, averaged over the rebuilds), ghosts per owned
// particle (halo fraction), the share of the wall time in communication (halo refresh, the
// end-of-step round that carries the step's reduction, migration), migrations, partitions, and
// the ceiling: the speedup if communication and waiting cost nothing (T1 over the largest
// per-rank time outside communication), which bounds what a faster transport could give.
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "io/deck.hpp"
#include "parallel/mpi_domain.hpp"
#include "settled_drum.hpp"

namespace {

using namespace dem2d;

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Args {
  std::vector<int> ranks{1, 2};
  int steps = 2000;
  int repeats = 3;
  double waterfall_time = 1.0;
  std::vector<std::int64_t> particles{30000};
  bool waterfall = true;
  bool plot = true;
  bool worker = false;
  std::string csv = "strong_scaling.csv";
  std::string results = std::string(DEM2D_SOURCE_DIR) + "/bench/results";
  std::string rows;  // worker: file to append rows to
};

struct Row {
  std::string scene;
  int ranks = 1;
  std::int64_t particles = 0, steps = 0;
  double wall = 0, compute = 0, imbalance = 1, halo_fraction = 0, comm_share = 0;
  double wall_max = 0;  // the slowest repeat
  double cpu = 0;       // the fastest repeat's CPU time of the timed loop, max over ranks
  std::int64_t migrated = 0;
  int partitions = 0;
};

Row measure(const std::string& name, const Scene& scene, int untimed, std::int64_t steps,
            int repeats, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  DecompositionOptions opt;
  opt.has_center = scene.drum.present;
  opt.center = scene.drum.center;
  opt.sectors_per_rank = scene.run.sectors_per_rank;
  opt.repartition_threshold = scene.run.repartition_threshold;
  MpiDomain domain(comm, opt);
  Simulation sim(scene, &domain);
  for (int k = 0; k < untimed; ++k) sim.step(/*end_observed=*/k + 1 == untimed);
  // The machine is shared: the timed segment is repeated (the run continues) and the fastest
  // of the repeats is kept, for the communication share too.
  double wall = 1e300, comm_max = 0.0, compute_max = 0.0, slowest = 0.0, cpu_max = 0.0;
  for (int rep = 0; rep < repeats; ++rep) {
    const double comm0 = domain.stats().comm_seconds;
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime(), c0 = cpu_seconds();
    for (std::int64_t k = 0; k < steps; ++k) sim.step(/*end_observed=*/k + 1 == steps);
    const double local = MPI_Wtime() - t0, cpu_local = cpu_seconds() - c0;
    double cpu_seg = 0.0;
    MPI_Allreduce(&cpu_local, &cpu_seg, 1, MPI_DOUBLE, MPI_MAX, comm);
    double seg = 0.0, comm_seg = 0.0;
    MPI_Allreduce(&local, &seg, 1, MPI_DOUBLE, MPI_MAX, comm);
    const double comm_local = domain.stats().comm_seconds - comm0;
    MPI_Allreduce(&comm_local, &comm_seg, 1, MPI_DOUBLE, MPI_MAX, comm);
    const double compute_local = local - comm_local;
    double compute_seg = 0.0;
    MPI_Allreduce(&compute_local, &compute_seg, 1, MPI_DOUBLE, MPI_MAX, comm);
    slowest = std::max(slowest, seg);
    if (seg < wall) {
      wall = seg;
      comm_max = comm_seg;
      compute_max = compute_seg;
      cpu_max = cpu_seg;
    }
  }
  Row r;
  r.scene = name;
  r.ranks = size;
  r.particles = domain.sum(static_cast<std::int64_t>(sim.particles().n_owned()));
  r.steps = steps;
  r.wall = wall;
  r.wall_max = slowest;
  r.cpu = cpu_max;
  r.compute = compute_max;
  r.imbalance = domain.stats().imbalance_mean();
  const std::int64_t ghosts = domain.sum(static_cast<std::int64_t>(sim.particles().n_ghost()));
  r.halo_fraction = static_cast<double>(ghosts) / static_cast<double>(r.particles);
  r.comm_share = comm_max / wall;
  r.migrated = domain.sum(domain.stats().migrated);
  r.partitions = domain.stats().partitions;
  return r;
}

std::string csv(const Row& r) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s,%d,%lld,%lld,%.6g,%.6g,%.6g,%.6g,%.6g,%lld,%d,%.6g,%.6g",
                r.scene.c_str(), r.ranks, static_cast<long long>(r.particles),
                static_cast<long long>(r.steps), r.wall, r.compute, r.imbalance, r.halo_fraction,
                r.comm_share, static_cast<long long>(r.migrated), r.partitions, r.wall_max, r.cpu);
  return buf;
}

int worker(const Args& a) {
  MPI_Init(nullptr, nullptr);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::vector<Row> rows;
  for (std::int64_t n : a.particles) {
    const std::optional<bench::Packing> pk = bench::cached_packing(n, a.results + "/cache");
    if (!pk) {
      if (rank == 0)
        std::fprintf(stderr,
                     "strong_scaling: no cached packing of %lld particles in %s/cache (run "
                     "build/bench/throughput --sections drum --particles %lld): skipped\n",
                     static_cast<long long>(n), a.results.c_str(), static_cast<long long>(n));
      continue;
    }
    const std::int64_t steps =
        n <= 30000 ? a.steps : std::max<std::int64_t>(50, a.steps * 30000 / n);
    rows.push_back(measure("drum" + std::to_string(n / 1000) + "k", bench::settled_scene(*pk, 1e-6),
                           300, steps, a.repeats, MPI_COMM_WORLD));
  }
  if (a.waterfall) {
    Scene s = load_deck(std::string(DEM2D_SOURCE_DIR) + "/inputs/waterfall_polygon.in");
    rows.push_back(measure("waterfall", s, 0,
                           static_cast<std::int64_t>(a.waterfall_time / s.run.dt + 0.5), a.repeats,
                           MPI_COMM_WORLD));
  }
  if (rank == 0) {
    std::ofstream out(a.rows, std::ios::app);
    for (const Row& r : rows) out << csv(r) << "\n";
  }
  MPI_Finalize();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int k = 1; k < argc; ++k) {
    const std::string s = argv[k];
    const auto next = [&]() -> std::string { return k + 1 < argc ? argv[++k] : ""; };
    if (s == "--worker")
      a.worker = true;
    else if (s == "--rows")
      a.rows = next();
    else if (s == "--steps")
      a.steps = std::atoi(next().c_str());
    else if (s == "--repeats")
      a.repeats = std::max(1, std::atoi(next().c_str()));
    else if (s == "--waterfall-time")
      a.waterfall_time = std::atof(next().c_str());
    else if (s == "--no-plot")
      a.plot = false;
    else if (s == "--no-waterfall")
      a.waterfall = false;
    else if (s == "--csv")
      a.csv = next();
    else if (s == "--particles") {
      a.particles.clear();
      std::stringstream ls(next());
      for (std::string t; std::getline(ls, t, ',');)
        a.particles.push_back(static_cast<std::int64_t>(std::atof(t.c_str())));
    } else if (s == "--results")
      a.results = next();
    else if (s == "--ranks") {
      a.ranks.clear();
      std::stringstream ls(next());
      for (std::string t; std::getline(ls, t, ',');) a.ranks.push_back(std::atoi(t.c_str()));
    } else {
      std::fprintf(stderr,
                   "usage: strong_scaling [--ranks 1,2] [--particles N1,N2,...] [--steps S] "
                   "[--repeats R] [--waterfall-time T] [--no-waterfall] [--no-plot] "
                   "[--results DIR] [--csv NAME]\n");
      return 2;
    }
  }
  if (a.worker) return worker(a);

  const std::string rows_path = a.results + "/strong_scaling.rows.tmp";
  std::remove(rows_path.c_str());
  std::printf("== strong_scaling: drums of");
  for (std::int64_t n : a.particles) std::printf(" %lld", static_cast<long long>(n));
  std::printf(" spheres (dt 1e-6, %d steps at <= 30 000)%s (%.3g s)\n", a.steps,
              a.waterfall ? " and waterfall" : ", no waterfall", a.waterfall_time);
  std::string particles;
  for (std::int64_t n : a.particles)
    particles += (particles.empty() ? "" : ",") + std::to_string(n);
  for (int np : a.ranks) {
    std::ostringstream cmd;
    cmd << "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np " << np
        << " --oversubscribe '" << argv[0] << "' --worker --rows '" << rows_path << "' --steps "
        << a.steps << " --repeats " << a.repeats << " --waterfall-time " << a.waterfall_time
        << " --results '" << a.results << "' --particles " << particles
        << (a.waterfall ? "" : " --no-waterfall");
    std::printf("$ %s\n", cmd.str().c_str());
    std::fflush(stdout);
    if (std::system(cmd.str().c_str()) != 0) {
      std::fprintf(stderr, "strong_scaling: the run at %d ranks failed\n", np);
      return 1;
    }
  }
  std::vector<Row> rows;
  std::ifstream in(rows_path);
  for (std::string line; std::getline(in, line);) {
    std::stringstream ls(line);
    Row r;
    std::string f;
    std::getline(ls, r.scene, ',');
    char c;
    long long p, st, mg;
    ls >> r.ranks >> c >> p >> c >> st >> c >> r.wall >> c >> r.compute >> c >> r.imbalance >> c >>
        r.halo_fraction >> c >> r.comm_share >> c >> mg >> c >> r.partitions >> c >> r.wall_max >>
        c >> r.cpu;
    r.particles = p;
    r.steps = st;
    r.migrated = mg;
    rows.push_back(r);
  }
  std::remove(rows_path.c_str());
  const std::string out_csv = a.results + "/" + a.csv;
  std::ofstream out(out_csv);
  out << "scene,ranks,particles,steps,wall,speedup,efficiency,imbalance,halo_fraction,comm_share,"
         "migrated,partitions,"
         "particle_steps_per_s,us_per_step,ceiling,wall_max,us_per_step_max,cpu,us_per_step_cpu\n";
  std::printf("\n%-10s %5s %9s %7s %9s %8s %6s %9s %6s %6s %9s %12s %8s %9s %9s %8s\n", "scene",
              "ranks", "particles", "steps", "wall (s)", "speedup", "eff.", "imbalance", "halo",
              "comm", "migrated", "p-steps/s", "us/step", "(slowest)", "(cpu)", "ceiling");
  for (const Row& r : rows) {
    double base = r.wall;
    for (const Row& q : rows)
      if (q.scene == r.scene && q.ranks == 1) base = q.wall;
    const double speedup = base / r.wall, eff = speedup / r.ranks;
    const double rate = static_cast<double>(r.particles) * r.steps / r.wall;
    const double us_per_step = 1e6 * r.wall / static_cast<double>(r.steps);
    const double ceiling = r.compute > 0.0 ? base / r.compute : 0.0;
    const double us_per_step_max = 1e6 * r.wall_max / static_cast<double>(r.steps);
    std::printf(
        "%-10s %5d %9lld %7lld %9.3f %8.2f %6.2f %9.3f %6.3f %6.3f %9lld %12.3g %8.1f %9.1f %9.1f "
        "%8.2f\n",
        r.scene.c_str(), r.ranks, static_cast<long long>(r.particles),
        static_cast<long long>(r.steps), r.wall, speedup, eff, r.imbalance, r.halo_fraction,
        r.comm_share, static_cast<long long>(r.migrated), rate, us_per_step, us_per_step_max,
        1e6 * r.cpu / static_cast<double>(r.steps), ceiling);
    out << r.scene << "," << r.ranks << "," << r.particles << "," << r.steps << "," << r.wall << ","
        << speedup << "," << eff << "," << r.imbalance << "," << r.halo_fraction << ","
        << r.comm_share << "," << r.migrated << "," << r.partitions << "," << rate << ","
        << us_per_step << "," << ceiling << "," << r.wall_max << "," << us_per_step_max << ","
        << r.cpu << "," << 1e6 * r.cpu / static_cast<double>(r.steps) << "\n";
  }
  out.close();
  std::printf("wrote %s\n", out_csv.c_str());
  if (a.plot) {
    const std::string cmd = "/usr/bin/python3 '" + std::string(DEM2D_SOURCE_DIR) +
                            "/post/plot_strong_scaling.py' '" + out_csv + "' -o '" +
                            out_csv.substr(0, out_csv.rfind('.')) + ".png'";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "strong_scaling: the plot failed\n");
  }
  return 0;
}
