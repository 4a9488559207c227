// throughput: particle-steps per second of one core, and how the cost scales with N.
//
// (a) 30 000 polydisperse steel spheres (r uniform in [6, 10] mm; thesis steel: E = 2e11 Pa,
//     G = 8e10 Pa, rho = 7800, e = 0.73, mu_s = 0.1, mu_r = 0.05; hertz-mindlin + epsd) settled
//     in the 2.5 m circular drum (sides = 0, fill fraction 0.31), then the drum turning at
//     1.5 rad/s with dt = 1e-6 s: the time of `steps` steps (after 500 untimed warm-up steps)
//     gives particle-steps/s, against the target of 15 million per second on one core.
//     (The drum starts at full speed: the measured steps are the first milliseconds of a
//     settled charge sheared by the shell, a dense bed of persistent contacts.)
// (b) The same for N = 1e3, 3e3, 1e4, 3e4, 1e5 (or --particles): same material and size law,
//     drum radius R = 2.5 m sqrt(N / 30 000) so that the fill fraction stays 0.31, and drum
//     speed 1.5 rad/s sqrt(2.5 m / R) so that the Froude number stays 0.57; N = 3e4 is case (a).
//     Steps per size: max(--steps, 3e7 / N), so each size runs at least ~3e7 particle-steps.
// (c) The waterfall deck (inputs/waterfall_polygon.in, 240 balls, 10 s at dt = 1e-5 s) run through
// the
//     Simulation API without output, against the target of 5 s.
//
// Settling (not timed) is described in bench/settled_drum.hpp: a soft settle with the drum
// still, the overlaps removed geometrically, then steel with the drum still until the contacts
// stop growing. Settled packings are cached in bench/results/cache/settled_drum_<N>.csv (the
// first run settles: ~20 min for all five sizes, 15 of them for 1e5; delete a file to settle
// again; --no-cache ignores the cache and does not write it). The measured run starts from
// the packing with the drum turning and runs 500 untimed steps first.
//
// Times are measured as wall time and as the process's CPU time (equal on an idle machine; on a
// shared machine the CPU time is the steadier measure). Output: a table, bench/results/
// throughput.csv and bench/results/throughput.png (post/plot_throughput.py, run through
// std::system; --no-plot skips it).
//
//   throughput [--quick] [--particles N1,N2,...] [--steps S] [--skip-waterfall] [--no-plot]
//              [--no-cache] [--results DIR]
//
// --quick: N = 1000, 3000; 300 steps (at least 3e6 / N); the waterfall for 1 s only.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/simulation.hpp"
#include "io/deck.hpp"
#include "settled_drum.hpp"

namespace {

using dem2d::Scene;
using dem2d::Simulation;
using Clock = std::chrono::steady_clock;

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Wall and CPU time of a stretch of code.
struct Stopwatch {
  Clock::time_point w0 = Clock::now();
  double c0 = cpu_seconds();
  double wall() const { return std::chrono::duration<double>(Clock::now() - w0).count(); }
  double cpu() const { return cpu_seconds() - c0; }
};

constexpr double kTargetRate = 15.0e6;    // particle-steps per second on one core
constexpr double kTargetWaterfall = 5.0;  // s of wall time for the waterfall deck's 10 s
constexpr int kWarmupSteps = 500;

struct Options {
  bool quick = false;
  bool waterfall = true;
  bool plot = true;
  bool cache = true;
  std::vector<std::int64_t> particles = {1000, 3000, 10000, 30000, 100000};
  std::int64_t steps = 2000;
  double min_particle_steps = 3.0e7;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
};

struct Row {
  std::string section;
  std::int64_t n = 0;
  double drum_radius = 0.0, drum_speed = 0.0, dt = 0.0;
  std::int64_t steps = 0;
  double wall = 0.0, cpu = 0.0;
  double contacts_per_particle = 0.0;
  std::int64_t neighbor_builds = 0;
  double settle_wall = 0.0, settle_time = 0.0;
  double rate_wall() const { return static_cast<double>(n) * steps / wall; }
  double rate_cpu() const { return static_cast<double>(n) * steps / cpu; }
  double ns_wall() const { return 1e9 / rate_wall(); }
  double ns_cpu() const { return 1e9 / rate_cpu(); }
};

Row measure_drum(const Options& opt, std::int64_t n) {
  Row row;
  row.section = "drum";
  row.n = n;
  row.drum_radius = bench::drum_radius_for(n);
  row.drum_speed = bench::drum_speed_for(row.drum_radius);
  row.dt = 1.0e-6;
  const bench::Packing pk =
      opt.cache ? bench::settled_packing(n, opt.results + "/cache") : bench::settle_packing(n);
  row.settle_wall = pk.settle_wall;
  row.settle_time = pk.settle_time;
  Simulation sim(bench::settled_scene(pk, row.dt));
  for (int k = 0; k < kWarmupSteps; ++k) sim.step();
  row.steps =
      std::max<std::int64_t>(opt.steps, static_cast<std::int64_t>(opt.min_particle_steps / n));
  const std::int64_t builds0 = sim.neighbor_builds();
  const Stopwatch sw;
  for (std::int64_t k = 0; k < row.steps; ++k) sim.step();
  row.wall = sw.wall();
  row.cpu = sw.cpu();
  row.neighbor_builds = sim.neighbor_builds() - builds0;
  row.contacts_per_particle = static_cast<double>(sim.last_totals().contacts) / n;
  const std::string settling =
      pk.from_cache ? "cache" : std::to_string(std::lround(pk.settle_wall)) + " s";
  std::printf(
      "%-9s %8lld %7.3f %7.3f %8.1e %7lld %9.3f %9.3f %10.3e %10.3e %8.1f %8.1f %9.2f %7lld %8s\n",
      row.section.c_str(), static_cast<long long>(n), row.drum_radius, row.drum_speed, row.dt,
      static_cast<long long>(row.steps), row.cpu, row.wall, row.rate_cpu(), row.rate_wall(),
      row.ns_cpu(), row.ns_wall(), row.contacts_per_particle,
      static_cast<long long>(row.neighbor_builds), settling.c_str());
  std::fflush(stdout);
  return row;
}

Row measure_waterfall(double duration) {
  Row row;
  row.section = "waterfall";
  Scene s = dem2d::load_deck(DEM2D_SOURCE_DIR "/inputs/waterfall_polygon.in");
  s.run.duration = duration;
  const Stopwatch build;
  Simulation sim(s);
  const double setup = build.wall();
  row.n = static_cast<std::int64_t>(sim.particles().n_owned());
  row.drum_radius = s.drum.radius;
  row.drum_speed = s.drum.speed;
  row.dt = sim.dt();
  const Stopwatch sw;
  sim.run_until(duration);
  row.wall = sw.wall();
  row.cpu = sw.cpu();
  row.steps = sim.step_count();
  row.neighbor_builds = sim.neighbor_builds();
  row.contacts_per_particle =
      static_cast<double>(sim.last_totals().contacts) / static_cast<double>(row.n);
  std::printf(
      "waterfall deck: %lld balls, %.1f s at dt = %.1e s (%lld steps): %.2f s wall, %.2f s CPU "
      "(construction %.3f s); %.3e particle-steps/s (CPU), %.1f ns per particle-step; %lld "
      "rebuilds\n",
      static_cast<long long>(row.n), duration, row.dt, static_cast<long long>(row.steps), row.wall,
      row.cpu, setup, row.rate_cpu(), row.ns_cpu(), static_cast<long long>(row.neighbor_builds));
  std::fflush(stdout);
  return row;
}

std::vector<std::int64_t> parse_list(const std::string& s) {
  std::vector<std::int64_t> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(static_cast<std::int64_t>(std::stod(item)));
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  bool particles_given = false, steps_given = false;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) {
        std::fprintf(stderr, "throughput: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++k];
    };
    if (a == "--quick") {
      o.quick = true;
    } else if (a == "--particles") {
      o.particles = parse_list(value());
      particles_given = true;
    } else if (a == "--steps") {
      o.steps = std::stoll(value());
      steps_given = true;
    } else if (a == "--skip-waterfall") {
      o.waterfall = false;
    } else if (a == "--no-plot") {
      o.plot = false;
    } else if (a == "--no-cache") {
      o.cache = false;
    } else if (a == "--results") {
      o.results = value();
    } else {
      std::fprintf(
          stderr,
          "usage: throughput [--quick] [--particles N1,N2,...] [--steps S] [--skip-waterfall] "
          "[--no-plot] [--no-cache] [--results DIR]\n");
      std::exit(a == "--help" || a == "-h" ? 0 : 2);
    }
  }
  if (o.quick) {
    if (!particles_given) o.particles = {1000, 3000};
    if (!steps_given) o.steps = 300;
    o.min_particle_steps = 3.0e6;
  }
  for (std::int64_t n : o.particles)
    if (n < 10) {
      std::fprintf(stderr, "throughput: --particles needs counts >= 10\n");
      std::exit(2);
    }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const Stopwatch total;
  std::filesystem::create_directories(opt.results);
  std::printf(
      "== throughput: polydisperse steel (r %g-%g mm), hertz-mindlin + epsd, circular drum, dt "
      "1e-6 s\n",
      1e3 * bench::kRadiusMin, 1e3 * bench::kRadiusMax);
  std::printf(
      "   target: %.0f million particle-steps/s on one core = %.1f ns per particle-step\n\n",
      kTargetRate / 1e6, 1e9 / kTargetRate);
  std::printf("%-9s %8s %7s %7s %8s %7s %9s %9s %10s %10s %8s %8s %9s %7s %8s\n", "section", "N",
              "R (m)", "w rad/s", "dt (s)", "steps", "cpu (s)", "wall (s)", "p-steps/s", "(wall)",
              "ns/p-st", "(wall)", "contacts", "builds", "settling");
  std::vector<Row> rows;
  for (std::int64_t n : opt.particles) {
    try {
      rows.push_back(measure_drum(opt, n));
    } catch (const std::exception& e) {
      std::printf("N = %lld failed: %s\n", static_cast<long long>(n), e.what());
    }
  }
  std::printf(
      "   (p-steps/s, ns/p-st: by CPU time, then by wall time; contacts: particle-particle plus "
      "wall\n"
      "    contacts per particle at the end; builds: neighbour rebuilds in the timed steps; "
      "settling: wall\n"
      "    time of the untimed settling, or 'cache')\n");
  if (!rows.empty()) {
    const Row* a = &rows.back();
    for (const Row& r : rows)
      if (r.n == 30000) a = &r;
    std::printf(
        "\n(a) N = %lld: %.3e particle-steps/s by CPU time (%.3e by wall time) = %.0f %% of the "
        "target of "
        "15e6/s\n",
        static_cast<long long>(a->n), a->rate_cpu(), a->rate_wall(),
        100.0 * a->rate_cpu() / kTargetRate);
    if (rows.size() >= 2) {
      const Row& lo = rows.front();
      const Row& hi = rows.back();
      const double slope = std::log(hi.ns_cpu() * static_cast<double>(hi.n) /
                                    (lo.ns_cpu() * static_cast<double>(lo.n))) /
                           std::log(static_cast<double>(hi.n) / static_cast<double>(lo.n));
      std::printf(
          "(b) cost per step grows as N^%.3f between N = %lld and %lld (1 = linear); ns per "
          "particle-step "
          "%.1f -> %.1f\n",
          slope, static_cast<long long>(lo.n), static_cast<long long>(hi.n), lo.ns_cpu(),
          hi.ns_cpu());
    }
  }
  if (opt.waterfall) {
    std::printf("\n");
    const double duration = opt.quick ? 1.0 : 10.0;
    try {
      const Row w = measure_waterfall(duration);
      std::printf("(c) waterfall %.0f s: %.2f s wall, %.2f s CPU against the target of %.1f s%s\n",
                  duration, w.wall, w.cpu, kTargetWaterfall * duration / 10.0,
                  opt.quick ? " (the 5 s target scaled to 1 s)" : "");
      rows.push_back(w);
    } catch (const std::exception& e) {
      std::printf("waterfall failed: %s\n", e.what());
    }
  }
  const std::string csv = opt.results + "/throughput.csv";
  {
    std::ofstream f(csv);
    f << "section,n_particles,drum_radius,drum_speed,dt,steps,wall,cpu,particle_steps_per_s_cpu,"
         "particle_steps_per_s_wall,ns_per_particle_step_cpu,ns_per_particle_step_wall,contacts_"
         "per_particle,"
         "neighbor_builds,settle_wall,settle_sim_time,target_particle_steps_per_s\n";
    for (const Row& r : rows)
      f << r.section << ',' << r.n << ',' << r.drum_radius << ',' << r.drum_speed << ',' << r.dt
        << ',' << r.steps << ',' << r.wall << ',' << r.cpu << ',' << r.rate_cpu() << ','
        << r.rate_wall() << ',' << r.ns_cpu() << ',' << r.ns_wall() << ','
        << r.contacts_per_particle << ',' << r.neighbor_builds << ',' << r.settle_wall << ','
        << r.settle_time << ',' << kTargetRate << '\n';
  }
  std::printf("wrote %s\n", csv.c_str());
  if (opt.plot) {
    const std::string png = opt.results + "/throughput.png";
    const std::string cmd = "/usr/bin/python3 " DEM2D_SOURCE_DIR "/post/plot_throughput.py '" +
                            csv + "' -o '" + png + "'";
    std::printf("$ %s\n", cmd.c_str());
    std::fflush(stdout);
    if (std::system(cmd.c_str()) != 0) std::printf("throughput: the plot script failed\n");
  }
  std::printf("throughput: total %.1f s wall, %.1f s CPU\n", total.wall(), total.cpu());
  return 0;
}
