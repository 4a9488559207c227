// checkpoint: what writing and reading a checkpoint costs, against particle count, on
// the ranks the program is launched with:
//
//   build/bench/checkpoint [--particles 1e3,1e4,1e5,1e6] [--packing lattice|settled]
//                          [--explicit-particles] [--steps S] [--repeats R] [--skip-waterfall]
//                          [--waterfall-time T] [--dir DIR] [--results DIR] [--no-plot] [--quick]
//   mpirun -np 2 --oversubscribe build/bench/checkpoint ...
//
// Scenes:
//  - lattice (default): N steel spheres (thesis steel, hertz-mindlin + epsd, as in bench/
//    settled_drum.hpp) on a dense triangular lattice of pitch 16 mm filled row by row from the
//    bottom of the circular drum of bench/settled_drum.hpp (radius 2.5 m sqrt(N / 30 000),
//    turning at its Froude-0.57 speed), radii 8 mm x (1 + 1e-5 u), u uniform in [-1, 1]: about
//    half of the neighbour pairs overlap by < 0.2 um, so the bed starts with ~1.5 contacts per
//    particle (a settled bed has 1.45-1.65) and is built at any N in seconds (settling 1e6
//    spheres would take hours). S steps of dt = 1e-6 s (default 20) give the contacts their
//    histories.
//  - settled (--packing settled): the settled packings of bench/throughput (cached in
//    DIR/cache/settled_drum_<N>.csv; settled first if absent: 1 s at 1e3, 33 s at 1e4, 15 min
//    at 1e5), S steps with the drum turning: a cross-check of the file size.
//  - waterfall: inputs/waterfall_polygon.in (240 balls) run to T simulated seconds (default 1), its
//    step time from 2000 steps.
// The lattice and settled particles enter the scene as a deck's `[[fill]] file = "..."` packing
// does (the resolved deck in the checkpoint names the file); --explicit-particles makes them
// [[particle]] tables instead, which the checkpoint's deck lists one by one (scene name
// "lattice-explicit": what that costs).
//
// For each scene: the median wall time of a step (max over ranks); write_checkpoint (R times,
// default 5; 4 R below 1e5 particles; median, min, max, and the median CPU time of the calling
// thread; each rank timed from a barrier, max over ranks; the write goes to the page cache, as
// in a run); fsync of the file (not part of dem2d's cost: the durable write); the restart,
// read_checkpoint then the resumed Simulation's constructor, R times after the file was evicted
// from the page cache with posix_fadvise(DONTNEED) (cold: from the disk) and R times with it
// cached (warm: a restart right after a stop); file size; peak RSS (max over ranks, since the
// program started). Rows go into DIR/checkpoint.csv, replacing earlier rows of the same scene,
// rank count and particle count (run once on 1 rank and once on 2 to fill it), then
// post/plot_checkpoint.py plots DIR/checkpoint.png.
#include "io/checkpoint.hpp"

#include <fcntl.h>
#include <mpi.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "blocks.hpp"
#include "core/run/simulation.hpp"
#include "io/deck.hpp"
#include "lists.hpp"
#include "parallel/mpi_domain.hpp"
#include "settled_drum.hpp"

namespace {

using namespace dem2d;

constexpr double kPitch = 0.016;  // m: lattice spacing = the mean diameter of [6, 10] mm spheres
constexpr double kJitter = 1e-5;  // relative spread of the radii about kPitch / 2
constexpr double kMargin = 1e-6;  // m: gap kept to the drum shell
constexpr double kLatticeDt = 1e-6;

struct Args {
  std::vector<std::int64_t> particles{1000, 10000, 100000, 1000000};
  std::string packing = "lattice";
  int steps = 20;
  int repeats = 5;
  bool waterfall = true;
  double waterfall_time = 1.0;
  bool plot = true;
  bool explicit_particles = false;  // the particles as [[particle]] tables in the deck
  std::string dir = "/tmp/dem2d-bench-checkpoint";
  std::string results = std::string(DEM2D_SOURCE_DIR) + "/bench/results";
};

struct Row {
  std::string scene;
  int ranks = 1;
  std::int64_t particles = 0, records = 0;
  double bytes = 0.0;
  int repeats = 0;
  double step = 0.0;  // median wall time of one step
  double write_med = 0.0, write_min = 0.0, write_max = 0.0, write_cpu = 0.0, fsync = 0.0;
  double read_warm = 0.0, restart_warm = 0.0, read_cold = 0.0, restart_cold = 0.0;
  double rss_mb = 0.0;
};

int rank_of(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Peak resident memory of this process (MB).
double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// N spheres on a triangular lattice filled row by row from the bottom of the drum.
Scene lattice_scene(std::int64_t n) {
  const double radius = bench::drum_radius_for(n);
  Scene s = bench::drum_scene(radius, bench::drum_speed_for(radius));
  s.title = "bench: a dense triangular lattice of steel spheres";
  s.materials = {bench::steel(1.0)};
  s.run.dt = kLatticeDt;
  s.run.dt_auto = false;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double r_max = 0.5 * kPitch * (1.0 + kJitter);
  const double row_height = 0.5 * std::sqrt(3.0) * kPitch;
  const auto half_sites = static_cast<int>(std::ceil(radius / kPitch)) + 1;
  s.particles.reserve(static_cast<std::size_t>(n));
  for (int row = 0; static_cast<std::int64_t>(s.particles.size()) < n; ++row) {
    const double y = -radius + r_max + kMargin + row * row_height;
    if (y > radius - r_max) throw std::runtime_error("lattice: the drum cannot hold the spheres");
    const double offset = row % 2 ? 0.5 * kPitch : 0.0;
    for (int k = -half_sites; k <= half_sites; ++k) {
      const Vec2 x{offset + k * kPitch, y};
      if (norm(x) + r_max + kMargin > radius) continue;
      if (static_cast<std::int64_t>(s.particles.size()) == n) break;
      ParticleSpec p;
      p.material = "steel";
      p.radius = 0.5 * kPitch * (1.0 + kJitter * u(rng));
      p.position = x;
      s.particles.push_back(p);
    }
  }
  return s;
}

// The settled packing of bench/throughput: rank 0 settles (or reads the cache) first.
Scene settled_scene(std::int64_t n, const Args& a, MPI_Comm comm) {
  bench::Packing pk;
  if (rank_of(comm) == 0) pk = bench::settled_packing(n, a.results + "/cache");
  MPI_Barrier(comm);
  if (rank_of(comm) != 0) pk = bench::settled_packing(n, a.results + "/cache", false);
  return bench::settled_scene(pk, kLatticeDt);
}

// The scene's particles as the deck parser leaves those of a `[[fill]] file = "..."` (a CSV
// packing, the way to start a large run from given positions): the resolved deck, which the
// checkpoint stores and a restart compares, names the file instead of listing every particle.
void as_file_fill(Scene& s, const std::string& label) {
  FillSpec f;
  f.material = "steel";
  f.file = label;
  f.count = static_cast<std::int64_t>(s.particles.size());
  s.file_fills = {f};
}

// Wall time of `f` from a barrier and the CPU time of this thread in it, the slowest rank's.
template <class F>
std::pair<double, double> timed(MPI_Comm comm, F&& f) {
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime(), c0 = bench::thread_cpu_seconds();
  f();
  const double wall = MPI_Wtime() - t0, cpu = bench::thread_cpu_seconds() - c0;
  return {mpi::max(comm, wall), mpi::max(comm, cpu)};
}

// Rank 0 flushes the file to the disk (returns the time that took) and drops it from the page
// cache, so that the next read comes from the disk.
double flush_and_evict(MPI_Comm comm, const std::string& path) {
  double took = 0.0;
  if (rank_of(comm) == 0) {
    const int fd = open(path.c_str(), O_RDONLY);
    if (fd >= 0) {
      const double t0 = MPI_Wtime();
      fsync(fd);
      took = MPI_Wtime() - t0;
      posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
      close(fd);
    }
  }
  MPI_Barrier(comm);
  return took;
}

// One restart: read_checkpoint, then the resumed Simulation (built on a fresh domain). Returns
// the read time and the whole restart's, each the slowest rank's.
std::pair<double, double> restart_once(MPI_Comm comm, const std::string& path, const Scene& scene) {
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime();
  double t_read = 0.0, t_all = 0.0;
  {
    const Resumption r = read_checkpoint(comm, path, scene);
    t_read = MPI_Wtime() - t0;
    MpiDomain domain(comm, decomposition_of(scene));
    const Simulation sim(scene, &domain, &r);
    t_all = MPI_Wtime() - t0;
  }
  return {mpi::max(comm, t_read), mpi::max(comm, t_all)};
}

// The median step time: `steps` steps timed one by one (at least one).
double step_time(MPI_Comm comm, Simulation& sim, int steps) {
  std::vector<double> t;
  for (int k = 0; k < std::max(1, steps); ++k) {
    const double t0 = MPI_Wtime();
    sim.step();
    t.push_back(MPI_Wtime() - t0);
  }
  return mpi::max(comm, median(t));
}

// Writes of the state of `sim`, the fsync of the file, then restarts from it: cold (each after
// the file was dropped from the page cache), then warm.
void time_checkpoint(MPI_Comm comm, const std::string& path, const Scene& scene,
                     const Simulation& sim, Row& row) {
  std::vector<double> w, wc, rw, aw, rc, ac;
  for (int k = 0; k < row.repeats; ++k) {
    const auto [wall, cpu] = timed(comm, [&] { write_checkpoint(comm, path, sim); });
    w.push_back(wall);
    wc.push_back(cpu);
  }
  row.write_med = median(w);
  row.write_cpu = median(wc);
  row.write_min = *std::min_element(w.begin(), w.end());
  row.write_max = *std::max_element(w.begin(), w.end());
  row.fsync = flush_and_evict(comm, path);
  for (int k = 0; k < row.repeats; ++k) {
    flush_and_evict(comm, path);
    const auto [read, all] = restart_once(comm, path, scene);
    rc.push_back(read);
    ac.push_back(all);
  }
  for (int k = 0; k < row.repeats; ++k) {
    const auto [read, all] = restart_once(comm, path, scene);
    rw.push_back(read);
    aw.push_back(all);
  }
  row.read_cold = median(rc);
  row.restart_cold = median(ac);
  row.read_warm = median(rw);
  row.restart_warm = median(aw);
  if (rank_of(comm) == 0) row.bytes = static_cast<double>(std::filesystem::file_size(path));
  MPI_Bcast(&row.bytes, 1, MPI_DOUBLE, 0, comm);
}

// One scene: built, run to `warm_time`, `steps` steps timed (which also give the lattice's
// contacts their histories), then its checkpoint measured.
Row measure(const Args& a, const std::string& name, const Scene& scene, double warm_time, int steps,
            MPI_Comm comm) {
  Row row;
  row.scene = name;
  MPI_Comm_size(comm, &row.ranks);
  MpiDomain domain(comm, decomposition_of(scene));
  Simulation sim(scene, &domain);
  if (warm_time > 0.0) sim.run_until(warm_time);
  row.step = step_time(comm, sim, steps);
  row.particles = mpi::sum(comm, static_cast<std::int64_t>(sim.particles().n_owned()));
  row.records = mpi::sum(comm, static_cast<std::int64_t>(sim.histories().size()));
  row.repeats = row.particles < 100000 ? 4 * a.repeats : a.repeats;
  time_checkpoint(comm, a.dir + "/checkpoint.h5", scene, sim, row);
  row.rss_mb = mpi::max(comm, peak_rss_mb());
  return row;
}

const char* kHeader =
    "scene,ranks,particles,contact_records,file_bytes,bytes_per_particle,repeats,step_s,"
    "write_median_s,write_min_s,write_max_s,write_cpu_s,fsync_s,"
    "read_warm_s,restart_warm_s,read_cold_s,restart_cold_s,write_in_steps,peak_rss_mb";

std::string csv_line(const Row& r) {
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "%s,%d,%lld,%lld,%.0f,%.2f,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.4g,"
      "%.1f",
      r.scene.c_str(), r.ranks, static_cast<long long>(r.particles),
      static_cast<long long>(r.records), r.bytes, r.bytes / static_cast<double>(r.particles),
      r.repeats, r.step, r.write_med, r.write_min, r.write_max, r.write_cpu, r.fsync, r.read_warm,
      r.restart_warm, r.read_cold, r.restart_cold, r.write_med / r.step, r.rss_mb);
  return buf;
}

void print_header() {
  std::printf("%-16s %5s %8s %8s %9s %7s %4s %9s %9s %9s %8s %9s %9s %9s %9s %8s %7s\n", "scene",
              "ranks", "N", "records", "size (MB)", "B/part", "reps", "step (s)", "write (s)",
              "w cpu", "fsync", "read warm", "restart w", "read cold", "restart c", "w/step",
              "RSS MB");
}

void print_row(const Row& r) {
  std::printf(
      "%-16s %5d %8lld %8lld %9.3f %7.1f %4d %9.3g %9.3g %9.3g %8.3g %9.3g %9.3g %9.3g %9.3g %8.3g "
      "%7.0f\n",
      r.scene.c_str(), r.ranks, static_cast<long long>(r.particles),
      static_cast<long long>(r.records), r.bytes / 1e6, r.bytes / static_cast<double>(r.particles),
      r.repeats, r.step, r.write_med, r.write_cpu, r.fsync, r.read_warm, r.restart_warm,
      r.read_cold, r.restart_cold, r.write_med / r.step, r.rss_mb);
  std::fflush(stdout);
}

// The CSV's rows, without those this run replaces (same scene, ranks and particles), plus ours.
void merge_csv(const std::string& path, const std::vector<Row>& rows) {
  std::vector<std::string> keep;
  std::ifstream in(path);
  std::string line;
  if (std::getline(in, line) && line == kHeader) {
    while (std::getline(in, line)) {
      std::stringstream ls(line);
      std::string scene, ranks, n;
      std::getline(ls, scene, ',');
      std::getline(ls, ranks, ',');
      std::getline(ls, n, ',');
      const bool replaced = std::any_of(rows.begin(), rows.end(), [&](const Row& r) {
        return r.scene == scene && std::to_string(r.ranks) == ranks &&
               std::to_string(r.particles) == n;
      });
      if (!replaced && !line.empty()) keep.push_back(line);
    }
  }
  for (const Row& r : rows) keep.push_back(csv_line(r));
  std::ofstream out(path);
  out << kHeader << "\n";
  for (const std::string& l : keep) out << l << "\n";
}

// Returns false on a bad command line.
bool parse(int argc, char** argv, Args& a) {
  for (int k = 1; k < argc; ++k) {
    const std::string s = argv[k];
    const auto next = [&]() -> std::string { return k + 1 < argc ? argv[++k] : ""; };
    if (s == "--particles")
      a.particles = bench::parse_list<std::int64_t>(next());
    else if (s == "--packing")
      a.packing = next();
    else if (s == "--steps")
      a.steps = std::max(1, std::atoi(next().c_str()));
    else if (s == "--repeats")
      a.repeats = std::max(1, std::atoi(next().c_str()));
    else if (s == "--skip-waterfall")
      a.waterfall = false;
    else if (s == "--waterfall-time")
      a.waterfall_time = std::atof(next().c_str());
    else if (s == "--dir")
      a.dir = next();
    else if (s == "--results")
      a.results = next();
    else if (s == "--no-plot")
      a.plot = false;
    else if (s == "--explicit-particles")
      a.explicit_particles = true;
    else if (s == "--quick") {
      a.particles = {1000, 10000};
      a.repeats = 2;
      a.waterfall_time = 0.1;
    } else
      return false;
  }
  return a.packing == "lattice" || a.packing == "settled";
}

std::vector<Row> run_all(const Args& a, MPI_Comm comm) {
  std::vector<Row> rows;
  const bool root = rank_of(comm) == 0;
  for (const std::int64_t n : a.particles) {
    Scene s = a.packing == "settled" ? settled_scene(n, a, comm) : lattice_scene(n);
    if (!a.explicit_particles) as_file_fill(s, "bench-" + a.packing + "-" + std::to_string(n));
    const std::string name = a.packing + (a.explicit_particles ? "-explicit" : "");
    rows.push_back(measure(a, name, s, 0.0, a.steps, comm));
    if (root) print_row(rows.back());
  }
  if (a.waterfall) {
    const Scene s = load_deck(std::string(DEM2D_SOURCE_DIR) + "/inputs/waterfall_polygon.in");
    rows.push_back(measure(a, "waterfall", s, a.waterfall_time, 2000, comm));
    if (root) print_row(rows.back());
  }
  return rows;
}

void report(const Args& a, const std::vector<Row>& rows) {
  std::printf(
      "   (times in s, medians, the slowest rank's; write: write_checkpoint into the page cache "
      "(wall; w cpu:\n    its main thread's CPU time); fsync: the durable flush after it; restart: "
      "read_checkpoint + the resumed "
      "Simulation; warm: file in the page\n    cache, cold: evicted first; w/step: the write "
      "in steps of this scene; RSS: peak so far)\n");
  for (const Row& r : rows)
    if (r.scene == "waterfall") {
      const double per_second = r.step / 1e-5;  // wall time of one simulated second (dt 1e-5 s)
      std::printf(
          "waterfall: one write %.3g ms wall (%.3g ms CPU) = %.0f steps; one write per simulated "
          "second ~ %.2f %% (%.2f %% by CPU) of the run (from the median step time)\n",
          1e3 * r.write_med, 1e3 * r.write_cpu, r.write_med / r.step,
          100.0 * r.write_med / per_second, 100.0 * r.write_cpu / per_second);
    }
  const std::string csv = a.results + "/checkpoint.csv";
  merge_csv(csv, rows);
  std::printf("wrote %s\n", csv.c_str());
  if (a.plot) {
    const std::string cmd = "/usr/bin/python3 '" + std::string(DEM2D_SOURCE_DIR) +
                            "/post/plot_checkpoint.py' '" + csv + "' -o '" + a.results +
                            "/checkpoint.png'";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "checkpoint: the plot failed\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  dem2d::mpi::init(&argc, &argv);
  Args a;
  const bool root = rank_of(MPI_COMM_WORLD) == 0;
  if (!parse(argc, argv, a)) {
    if (root)
      std::fprintf(stderr,
                   "usage: checkpoint [--particles N1,N2,...] [--packing lattice|settled] "
                   "[--explicit-particles] [--steps S] [--repeats R] [--skip-waterfall] "
                   "[--waterfall-time T] [--dir DIR] "
                   "[--results DIR] [--no-plot] [--quick]\n");
    MPI_Finalize();
    return 2;
  }
  if (root) {
    std::filesystem::create_directories(a.dir);
    std::filesystem::create_directories(a.results);
    std::printf("== checkpoint: write and restart cost against N (%s), files in %s\n",
                a.packing.c_str(), a.dir.c_str());
    print_header();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  const std::vector<Row> rows = run_all(a, MPI_COMM_WORLD);
  if (root) {
    report(a, rows);
    std::filesystem::remove(a.dir + "/checkpoint.h5");
  }
  MPI_Finalize();
  return 0;
}
