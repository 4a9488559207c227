// throughput: particle-steps per second of one core, how the cost scales with N and with the
// size ratio, and what memory a particle takes.
//
// Sections (--sections, default all but order, in this order):
// drum       The settled polydisperse steel drum (bench/settled_drum.hpp: r uniform in
//            [6, 10] mm; thesis steel: E = 2e11 Pa, G = 8e10 Pa, rho = 7800, e = 0.73,
//            mu_s = 0.1, mu_r = 0.05; hertz-mindlin + epsd; circular drum, sides = 0, fill
//            fraction 0.31) for N = 1e3, 3e3, 1e4, 3e4, 1e5 (--particles): drum radius
//            R = 2.5 m sqrt(N / 30 000), speed 1.5 rad/s sqrt(2.5 m / R) (Froude 0.57),
//            dt = 1e-6 s. N = 3e4 is the reference scene (target 15 million particle-steps/s).
//            N < 3e5 are settled by dynamics; N >= 3e5 given here are the deposited beds below.
//            Steps per repeat: min(max(--steps, 3e7 / N), 3e8 / N): 30 000 at 1e3, 2 000 at
//            3e4 and 1e5, 1 000 at 3e5, 300 at 1e6.
// deposited  The same drums built by deposition and loaded (settled_drum.hpp, deposit_packing:
//            no dynamics until the loading, so a million particles take minutes, not hours)
//            for N = 1e4, 3e4, 1e5, 1e6 (--deposited): one recipe at every size, so the cost
//            per particle-step is compared to the 1e4 bed of the same recipe (target of
//            bound: within 1.3x up to 1e6). Measured in the material they are loaded in
//            (steel with e = 0.1, mu_s = 0.5: the thesis steel cannot hold a deposited bed) and
//            with the drum still (--deposited-speed F: F times the drum's full speed): started
//            at full speed with this friction, the smaller beds dilate at the shell within the
//            measured steps (1e4: 1.12 contacts per particle, 1e5: 1.78), which would measure
//            the bed, not the code. Steps per repeat as for the drum.
// ratios     Size ratio r_max / r_min = 1, 2, 5, 10 (--ratios) at the same count N = 20 000
//            (--ratio-particles) and fill fraction 0.31: radii log-uniform in
//            [10 mm / ratio, 10 mm] (ratio 1: all 10 mm), drum radius sqrt(sum r^2 / 0.31),
//            speed as above, dt = 5e-7 s for every ratio (1 mm steel spheres need it); settled
//            by the same three stages from a random sequential placement (settled_drum.hpp).
//            Reported against the monodisperse cost (bound: 10:1 within 1.5x).
//            Steps per repeat: max(--steps, 3e7 / N).
// block      The dense sliding block: the thesis charge of inputs/waterfall_polygon.in (240
//            balls of 0.1 m, friction 0.1) in a circular shell (--set drum.sides=0), through the
//            Simulation API without output: the first --block-warmup s (2 s) untimed (the 0.5 s
//            ramp, then the charge slides and rocks as one block on the smooth shell), then
//            --repeats segments of --block-time s (2.5 s) timed; contacts and candidate pairs
//            per particle are the means of samples every 10 ms of the timed segments. Target of
//            target: 40 million particle-steps/s.
// order      Storage order (run.spatial_sort, core/fast/spatial_order.hpp): the drum packings of
//            --order-particles (default 1e5, 1e6) with their ids as the fill gave them (row by
//            row: spatially coherent) and shuffled (a fixed random permutation: ids spatially
//            random, as in a long-mixed charge or after grinding), each with the store kept in
//            id order ("never") and as "auto" chooses (1e6 shuffled: sorted along the Hilbert
//            curve, the list in storage order, forces summed through the records). Not in the
//            default sections.
// waterfall  The waterfall deck (inputs/waterfall_polygon.in, 10 s at dt = 1e-5 s) run through
//            the Simulation API without output, against the target of 5 s (once, as before).
//
// Drum and ratio runs: the packing (cached in --results/cache, see settled_drum.hpp) becomes a
// scene with the drum turning at full speed; 500 untimed warm-up steps, then --repeats
// consecutive timed segments (default 2); the fastest segment by CPU time is reported, the
// slowest too (spread). Contacts (particle-particle plus wall, the core's count), particle-
// particle contacts alone (touching pairs of the pair list, counted by the bench) and candidate
// pairs (listed particle-particle pairs) per particle are taken after the last segment.
//
// Memory per particle: the growth of the process's resident memory (VmRSS of
// /proc/self/status, read after the scene is built and malloc_trim(0), and again after the
// warm-up) divided by N: the Simulation with its copy of the scene, lists and buffers; the
// particle store's ParticleStore::bytes_per_particle() (its registered fields); and the bytes
// allocated (capacity) by the pair list and the wall-pair list with their histories, per
// particle.
//
// Times are wall time and the process's CPU time (equal on an idle machine; on a shared machine
// the CPU time is the steadier measure). Output: a table, DIR/throughput.csv (one row per run:
// section, N, size ratio, ...) and DIR/throughput.png (post/plot_throughput.py through
// std::system; --no-plot skips it).
//
//   throughput [--sections drum,deposited,ratios,block,waterfall,order] [--quick]
//              [--particles N1,...] [--deposited N1,...] [--deposited-speed F] [--ratios R1,R2,...]
//              [--ratio-particles N]
//              [--steps S] [--repeats R]
//              [--block-warmup T] [--block-time T] [--skip-waterfall] [--no-plot] [--no-cache]
//              [--results DIR] [--csv NAME] [--order-particles N1,N2,...]
//   throughput --profile-block STEPS      (bench/profile_contacts.sh)
//   throughput --profile-drum N STEPS
//
// Without --sections all but order run; --particles without --sections runs the drum section and
// the waterfall only, as the program did before it had sections; --skip-waterfall drops the
// waterfall from either. --quick: N = 1000, 3000, deposited 3000, 10000, ratios at N = 2000, 300
// steps (at least 3e6 / N), block 0.5 s + 2 x 0.25 s, the waterfall for 1 s. --csv NAME: write
// DIR/NAME instead of DIR/throughput.csv (the plot goes beside it with .png). --profile-*: set up
// the scene (the drum's from the cache, which must exist), run the untimed warm-up, then only STEPS
// steps in profiled_steps() and print one line with the particle-steps, contact-steps and
// candidate-steps and the CPU time of those steps alone (ns per particle-step); no table, no files.
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "core/run/simulation.hpp"
#include "io/deck.hpp"
#include "lists.hpp"
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

// Resident memory of the process (VmRSS), bytes.
double rss_bytes() {
  std::ifstream f("/proc/self/status");
  for (std::string line; std::getline(f, line);)
    if (line.rfind("VmRSS:", 0) == 0) return 1024.0 * std::atof(line.c_str() + 6);
  return 0.0;
}

template <class List>
double list_bytes(const List& l) {
  return static_cast<double>(l.history.capacity() * sizeof(double) +
                             l.trial.capacity() * sizeof(double));
}
double pair_list_bytes(const dem2d::PairList& l) {
  return list_bytes(l) +
         static_cast<double>(l.i.capacity() * sizeof(l.i[0]) + l.j.capacity() * sizeof(l.j[0]) +
                             l.id_i.capacity() * sizeof(l.id_i[0]) +
                             l.id_j.capacity() * sizeof(l.id_j[0]));
}
double wall_list_bytes(const dem2d::WallPairList& l) {
  return list_bytes(l) + static_cast<double>(l.particle.capacity() * sizeof(l.particle[0]) +
                                             l.element.capacity() * sizeof(l.element[0]) +
                                             l.id.capacity() * sizeof(l.id[0]));
}

constexpr double kTargetRate = 15.0e6;    // particle-steps per second on one core
constexpr double kTargetWaterfall = 5.0;  // s of wall time for the waterfall deck's 10 s
constexpr double kTargetBlock = 40.0e6;   // particle-steps per second
constexpr double kTargetRatioCost = 1.5;  // 10:1 against monodisperse
constexpr int kWarmupSteps = 500;
const char* const kDeck = DEM2D_SOURCE_DIR "/inputs/waterfall_polygon.in";

struct Options {
  bool quick = false;
  std::vector<std::string> sections = {"drum", "deposited", "ratios", "block", "waterfall"};
  bool plot = true;
  bool cache = true;
  std::vector<std::int64_t> particles = {1000, 3000, 10000, 30000, 100000};
  std::vector<std::int64_t> deposited = {10000, 30000, 100000, 1000000};
  double deposited_speed = 0.0;
  std::vector<double> ratios = {1.0, 2.0, 5.0, 10.0};
  std::int64_t ratio_particles = 20000;
  std::vector<std::int64_t> order_particles = {100000, 1000000};
  std::int64_t steps = 2000;
  int repeats = 2;
  double min_particle_steps = 3.0e7;
  double max_particle_steps = 3.0e8;
  double block_warmup = 2.0, block_time = 2.5;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
  std::string csv = "throughput.csv";
  // --profile-block / --profile-drum
  std::string profile;
  std::int64_t profile_n = 0, profile_steps = 0;
  bool has(const std::string& s) const {
    return std::find(sections.begin(), sections.end(), s) != sections.end();
  }
};

struct Row {
  std::string section;
  std::int64_t n = 0;
  double ratio = 0.0;  // r_max / r_min (ratio section; drum: 10/6; block, waterfall: 1)
  double drum_radius = 0.0, drum_speed = 0.0, dt = 0.0;
  std::int64_t steps = 0;  // per repeat
  int repeats = 1;
  double wall = 0.0, cpu = 0.0;  // the fastest repeat (by CPU time)
  double cpu_max = 0.0;          // the slowest repeat
  double contacts_per_particle = 0.0, candidates_per_particle = 0.0;
  double pair_contacts_per_particle = 0.0;  // particle-particle only (no wall contacts)
  std::int64_t neighbor_builds = 0;         // in all timed repeats
  double settle_wall = 0.0, settle_time = 0.0;
  double rss_per_particle = 0.0, store_per_particle = 0.0, pairs_per_particle = 0.0;
  // ratio section: ns per particle-step / that of ratio 1; order: / that of the id-order store
  double cost_vs_mono = 0.0;
  // Storage order: the ids as filled ("fill") or shuffled, the run.spatial_sort mode, and the
  // sorts the run made (in its warm-up and timed steps).
  std::string ids = "fill";
  dem2d::SpatialSort sort = dem2d::SpatialSort::kAuto;
  std::int64_t sorts = 0;
  double rate_wall() const { return static_cast<double>(n) * steps / wall; }
  double rate_cpu() const { return static_cast<double>(n) * steps / cpu; }
  double ns_wall() const { return 1e9 / rate_wall(); }
  double ns_cpu() const { return 1e9 / rate_cpu(); }
  double spread() const { return cpu_max / cpu - 1.0; }
};

const char* sort_name(dem2d::SpatialSort s) {
  return s == dem2d::SpatialSort::kNever    ? "never"
         : s == dem2d::SpatialSort::kAlways ? "always"
                                            : "auto";
}

// Touching particle-particle pairs of the pair list (the bench's own count: the core counts
// particle-particle and wall contacts together).
double pair_contacts(const Simulation& sim) {
  const dem2d::ParticleStore& q = sim.particles();
  const dem2d::PairList& l = sim.pairs();
  std::int64_t touching = 0;
  for (std::size_t k = 0; k < l.size(); ++k) {
    const auto i = static_cast<std::size_t>(l.i[k]), j = static_cast<std::size_t>(l.j[k]);
    if (dem2d::norm(q.pos[j] - q.pos[i]) < q.radius[i] + q.radius[j]) ++touching;
  }
  return static_cast<double>(touching);
}

// The timed steps of the profiles: a function of its own so that a profiler can single it out.
[[gnu::noinline]] void profiled_steps(Simulation& sim, std::int64_t steps, double& contacts,
                                      double& candidates) {
  for (std::int64_t k = 0; k < steps; ++k) {
    sim.step(/*end_observed=*/k + 1 == steps);  // the counts below read no particle
    contacts += static_cast<double>(sim.last_totals().contacts);
    candidates += static_cast<double>(sim.pairs().size());
  }
}

// Warm-up, memory, then `repeats` timed segments of `steps` steps of a drum or ratio scene.
Row measure_packing(const Options& opt, const bench::Packing& pk, double dt, Row row,
                    double speed_factor = 1.0) {
  Scene scene = bench::settled_scene(pk, dt);
  scene.drum.speed *= speed_factor;
  scene.run.spatial_sort = row.sort;
  if (row.ids == "shuffled") {  // ids follow the order of the [[particle]] list
    std::mt19937_64 random(7);
    std::shuffle(scene.particles.begin(), scene.particles.end(), random);
  }
  row.n = static_cast<std::int64_t>(pk.pos.size());
  row.drum_radius = scene.drum.radius;
  row.drum_speed = scene.drum.speed;
  row.dt = dt;
  row.settle_wall = pk.settle_wall;
  row.settle_time = pk.settle_time;
  malloc_trim(0);
  const double rss0 = rss_bytes();
  Simulation sim(scene);
  for (int k = 0; k < kWarmupSteps; ++k) sim.step(/*end_observed=*/k + 1 == kWarmupSteps);
  const auto n = static_cast<double>(row.n);
  row.rss_per_particle = (rss_bytes() - rss0) / n;
  row.store_per_particle = static_cast<double>(sim.particles().bytes_per_particle());
  row.repeats = opt.repeats;
  const std::int64_t builds0 = sim.neighbor_builds();
  for (int rep = 0; rep < opt.repeats; ++rep) {
    const Stopwatch sw;
    for (std::int64_t k = 1; k <= row.steps; ++k) sim.step(/*end_observed=*/k == row.steps);
    const double cpu = sw.cpu(), wall = sw.wall();
    if (rep == 0 || cpu < row.cpu) {
      row.cpu = cpu;
      row.wall = wall;
    }
    row.cpu_max = std::max(row.cpu_max, cpu);
  }
  row.neighbor_builds = sim.neighbor_builds() - builds0;
  row.sorts = sim.spatial_sorts();
  row.contacts_per_particle = static_cast<double>(sim.last_totals().contacts) / n;
  row.candidates_per_particle = static_cast<double>(sim.pairs().size()) / n;
  row.pair_contacts_per_particle = pair_contacts(sim) / n;
  row.pairs_per_particle = (pair_list_bytes(sim.pairs()) + wall_list_bytes(sim.wall_pairs())) / n;
  return row;
}

void print_header() {
  std::printf("%-9s %8s %5s %6s %6s %7s %6s %8s %6s %9s %7s %7s %6s %6s %6s %6s %6s %6s %s\n",
              "section", "N", "ratio", "R (m)", "w", "dt (s)", "steps", "cpu (s)", "spread",
              "p-steps/s", "ns/p-st", "(wall)", "contac", "candid", "builds", "B RSS", "B sto",
              "B pair", "settling");
}

void print_row(const Row& r, const std::string& settling) {
  std::printf(
      "%-9s %8lld %5.3g %6.3f %6.3f %7.1e %3lldx%-2d %8.3f %5.1f%% %9.3e %7.1f %7.1f %6.2f %6.2f "
      "%6lld %6.0f %6.0f %6.0f %s\n",
      r.section.c_str(), static_cast<long long>(r.n), r.ratio, r.drum_radius, r.drum_speed, r.dt,
      static_cast<long long>(r.steps), r.repeats, r.cpu, 100.0 * r.spread(), r.rate_cpu(),
      r.ns_cpu(), r.ns_wall(), r.contacts_per_particle, r.candidates_per_particle,
      static_cast<long long>(r.neighbor_builds), r.rss_per_particle, r.store_per_particle,
      r.pairs_per_particle, settling.c_str());
  std::fflush(stdout);
}

std::string settling_of(const bench::Packing& pk) {
  return pk.from_cache ? "cache" : std::to_string(std::lround(pk.settle_wall)) + " s";
}

// A drum of n particles: the settled packing, or (`deposited`) the deposited bed with the drum at
// --deposited-speed.
Row measure_drum(const Options& opt, std::int64_t n, bool deposited) {
  Row row;
  row.section = deposited ? "deposited" : "drum";
  row.ratio = bench::kRadiusMax / bench::kRadiusMin;
  const std::string cache = opt.results + "/cache";
  const bench::Packing pk = deposited   ? bench::deposited_packing(n, cache)
                            : opt.cache ? bench::settled_packing(n, cache)
                                        : bench::settle_packing(n);
  const auto nd = static_cast<double>(n);
  row.steps = std::min(std::max(opt.steps, static_cast<std::int64_t>(opt.min_particle_steps / nd)),
                       static_cast<std::int64_t>(opt.max_particle_steps / nd));
  row = measure_packing(opt, pk, 1.0e-6, row, deposited ? opt.deposited_speed : 1.0);
  print_row(row, settling_of(pk));
  return row;
}

// measure_drum for each size; a size that fails is reported and left out.
std::vector<Row> measure_drums(const Options& opt, const std::vector<std::int64_t>& sizes,
                               bool deposited) {
  std::vector<Row> out;
  for (std::int64_t n : sizes) {
    try {
      out.push_back(measure_drum(opt, n, deposited));
    } catch (const std::exception& e) {
      std::printf("%s N = %lld failed: %s\n", deposited ? "deposited" : "drum",
                  static_cast<long long>(n), e.what());
    }
  }
  return out;
}

Row measure_ratio(const Options& opt, double ratio) {
  Row row;
  row.section = "ratio";
  row.ratio = ratio;
  const std::int64_t n = opt.ratio_particles;
  const std::string cache = opt.results + "/cache";
  const bench::Packing pk =
      opt.cache ? bench::ratio_packing(n, ratio, cache) : bench::settle_ratio_packing(n, ratio);
  row.steps = std::max(opt.steps,
                       static_cast<std::int64_t>(opt.min_particle_steps / static_cast<double>(n)));
  row = measure_packing(opt, pk, bench::kRatioDt, row);
  print_row(row, settling_of(pk));
  return row;
}

// The dense sliding block's scene: the waterfall deck's charge in a circular shell.
Scene block_scene(double duration) {
  Scene s = dem2d::load_deck(kDeck, {"drum.sides=0"});
  s.run.duration = duration;
  return s;
}

Row measure_block(const Options& opt) {
  Row row;
  row.section = "block";
  row.ratio = 1.0;
  const Scene s = block_scene(opt.block_warmup + opt.repeats * opt.block_time);
  malloc_trim(0);
  const double rss0 = rss_bytes();
  Simulation sim(s);
  sim.run_until(opt.block_warmup);
  row.n = static_cast<std::int64_t>(sim.particles().n_owned());
  const auto n = static_cast<double>(row.n);
  row.rss_per_particle = (rss_bytes() - rss0) / n;
  row.store_per_particle = static_cast<double>(sim.particles().bytes_per_particle());
  row.drum_radius = s.drum.radius;
  row.drum_speed = s.drum.speed;
  row.dt = sim.dt();
  row.repeats = opt.repeats;
  const std::int64_t builds0 = sim.neighbor_builds();
  double contacts = 0.0, candidates = 0.0, pair_touching = 0.0;
  int samples = 0;
  for (int rep = 0; rep < opt.repeats; ++rep) {
    const std::int64_t step0 = sim.step_count();
    const double t_end = opt.block_warmup + (rep + 1) * opt.block_time;
    const Stopwatch sw;
    // Samples every 10 ms: a few counter reads per 1000 steps, nothing against the steps.
    for (double t = sim.time() + 0.01; t < t_end + 0.005; t += 0.01) {
      sim.run_until(std::min(t, t_end));
      contacts += static_cast<double>(sim.last_totals().contacts);
      candidates += static_cast<double>(sim.pairs().size());
      pair_touching += pair_contacts(sim);
      ++samples;
    }
    const double cpu = sw.cpu(), wall = sw.wall();
    row.steps = sim.step_count() - step0;
    if (rep == 0 || cpu < row.cpu) {
      row.cpu = cpu;
      row.wall = wall;
    }
    row.cpu_max = std::max(row.cpu_max, cpu);
  }
  row.neighbor_builds = sim.neighbor_builds() - builds0;
  row.contacts_per_particle = contacts / samples / n;
  row.candidates_per_particle = candidates / samples / n;
  row.pair_contacts_per_particle = pair_touching / samples / n;
  row.pairs_per_particle = (pair_list_bytes(sim.pairs()) + wall_list_bytes(sim.wall_pairs())) / n;
  print_row(row, "-");
  return row;
}

Row measure_waterfall(double duration) {
  Row row;
  row.section = "waterfall";
  row.ratio = 1.0;
  Scene s = dem2d::load_deck(kDeck);
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
  row.cpu_max = row.cpu;
  row.steps = sim.step_count();
  row.neighbor_builds = sim.neighbor_builds();
  row.contacts_per_particle =
      static_cast<double>(sim.last_totals().contacts) / static_cast<double>(row.n);
  row.candidates_per_particle =
      static_cast<double>(sim.pairs().size()) / static_cast<double>(row.n);
  row.store_per_particle = static_cast<double>(sim.particles().bytes_per_particle());
  std::printf(
      "waterfall deck: %lld balls, %.1f s at dt = %.1e s (%lld steps): %.2f s wall, %.2f s CPU "
      "(construction %.3f s); %.3e particle-steps/s (CPU), %.1f ns per particle-step; %lld "
      "rebuilds\n",
      static_cast<long long>(row.n), duration, row.dt, static_cast<long long>(row.steps), row.wall,
      row.cpu, setup, row.rate_cpu(), row.ns_cpu(), static_cast<long long>(row.neighbor_builds));
  std::fflush(stdout);
  return row;
}

// --profile-block / --profile-drum: set-up and warm-up, then only the profiled steps.
int run_profile(const Options& opt) {
  std::unique_ptr<Simulation> sim;
  if (opt.profile == "block") {
    Scene s = block_scene(0.0);
    s.run.duration = opt.block_warmup + static_cast<double>(opt.profile_steps) * s.run.dt + 1.0;
    sim = std::make_unique<Simulation>(s);
    sim->run_until(opt.block_warmup);
  } else {
    const std::optional<bench::Packing> pk =
        bench::cached_packing(opt.profile_n, opt.results + "/cache");
    if (!pk) {
      std::fprintf(stderr, "throughput: no cached packing of %lld particles in %s/cache\n",
                   static_cast<long long>(opt.profile_n), opt.results.c_str());
      return 1;
    }
    sim = std::make_unique<Simulation>(bench::settled_scene(*pk, 1.0e-6));
    for (int k = 0; k < kWarmupSteps; ++k) sim->step();
  }
  double contacts = 0.0, candidates = 0.0;
  const double c0 = cpu_seconds();
  profiled_steps(*sim, opt.profile_steps, contacts, candidates);
  const double cpu = cpu_seconds() - c0;
  const auto n = static_cast<double>(sim->particles().n_owned());
  const double particle_steps = n * static_cast<double>(opt.profile_steps);
  std::printf(
      "profile %s: particles %.0f steps %lld particle_steps %.0f contact_steps %.0f "
      "candidate_steps %.0f cpu_s %.4f ns_per_particle_step %.2f\n",
      opt.profile.c_str(), n, static_cast<long long>(opt.profile_steps), particle_steps, contacts,
      candidates, cpu, 1e9 * cpu / particle_steps);
  return 0;
}

[[noreturn]] void usage(int code) {
  std::fprintf(
      code ? stderr : stdout,
      "usage: throughput [--sections drum,deposited,ratios,block,waterfall,order] [--quick]\n"
      "                  [--particles N1,N2,...] [--deposited N1,N2,...] [--deposited-speed F]\n"
      "                  [--ratios R1,R2,...] [--ratio-particles N] [--steps S] [--repeats R]\n"
      "                  [--block-warmup T] [--block-time T] [--skip-waterfall] [--no-plot]\n"
      "                  [--no-cache] [--results DIR] [--csv NAME] [--order-particles N1,...]\n"
      "       throughput --profile-block STEPS | --profile-drum N STEPS [--results DIR]\n");
  std::exit(code);
}

Options parse(int argc, char** argv) {
  Options o;
  bool particles_given = false, steps_given = false, ratio_n_given = false, sections_given = false,
       skip_waterfall = false, deposited_given = false;
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
    } else if (a == "--sections") {
      sections_given = true;
      o.sections.clear();
      std::stringstream in(value());
      for (std::string s; std::getline(in, s, ',');) {
        if (s != "drum" && s != "deposited" && s != "ratios" && s != "block" && s != "waterfall" &&
            s != "order") {
          std::fprintf(stderr, "throughput: unknown section '%s'\n", s.c_str());
          usage(2);
        }
        o.sections.push_back(s);
      }
    } else if (a == "--particles") {
      o.particles = bench::parse_list<std::int64_t>(value());
      particles_given = true;
    } else if (a == "--deposited") {
      o.deposited = bench::parse_list<std::int64_t>(value());
      deposited_given = true;
    } else if (a == "--deposited-speed") {
      o.deposited_speed = std::stod(value());
    } else if (a == "--order-particles") {
      o.order_particles = bench::parse_list<std::int64_t>(value());
    } else if (a == "--ratios") {
      o.ratios = bench::parse_list<double>(value());
    } else if (a == "--ratio-particles") {
      o.ratio_particles = static_cast<std::int64_t>(std::stod(value()));
      ratio_n_given = true;
    } else if (a == "--steps") {
      o.steps = std::stoll(value());
      steps_given = true;
    } else if (a == "--repeats") {
      o.repeats = std::max(1, std::stoi(value()));
    } else if (a == "--block-warmup") {
      o.block_warmup = std::stod(value());
    } else if (a == "--block-time") {
      o.block_time = std::stod(value());
    } else if (a == "--skip-waterfall") {
      skip_waterfall = true;
    } else if (a == "--no-plot") {
      o.plot = false;
    } else if (a == "--no-cache") {
      o.cache = false;
    } else if (a == "--results") {
      o.results = value();
    } else if (a == "--csv") {
      o.csv = value();
    } else if (a == "--profile-block") {
      o.profile = "block";
      o.profile_steps = std::stoll(value());
    } else if (a == "--profile-drum") {
      o.profile = "drum";
      o.profile_n = static_cast<std::int64_t>(std::stod(value()));
      o.profile_steps = std::stoll(value());
    } else {
      usage(a == "--help" || a == "-h" ? 0 : 2);
    }
  }
  // --particles without --sections: the drum sizes (and the waterfall), as before the sections.
  if (particles_given && !sections_given) o.sections = {"drum", "waterfall"};
  if (skip_waterfall) std::erase(o.sections, std::string("waterfall"));
  if (o.quick) {
    if (!particles_given) o.particles = {1000, 3000};
    if (!deposited_given) o.deposited = {3000, 10000};
    if (!ratio_n_given) o.ratio_particles = 2000;
    if (!steps_given) o.steps = 300;
    o.min_particle_steps = 3.0e6;
    o.block_warmup = 0.5;
    o.block_time = 0.25;
  }
  for (std::int64_t n : o.particles)
    if (n < 10) {
      std::fprintf(stderr, "throughput: --particles needs counts >= 10\n");
      std::exit(2);
    }
  for (double r : o.ratios)
    if (!(r >= 1.0)) {
      std::fprintf(stderr, "throughput: --ratios needs ratios >= 1\n");
      std::exit(2);
    }
  return o;
}

void write_csv(const std::string& csv, const std::vector<Row>& rows) {
  std::ofstream f(csv);
  f << "section,n_particles,drum_radius,drum_speed,dt,steps,wall,cpu,particle_steps_per_s_cpu,"
       "particle_steps_per_s_wall,ns_per_particle_step_cpu,ns_per_particle_step_wall,contacts_"
       "per_particle,neighbor_builds,settle_wall,settle_sim_time,target_particle_steps_per_s,"
       "size_ratio,repeats,cpu_max,candidates_per_particle,rss_bytes_per_particle,store_bytes_"
       "per_particle,pair_bytes_per_particle,cost_vs_mono,pair_contacts_per_particle,ids,"
       "spatial_sort,sorts\n";
  for (const Row& r : rows)
    f << r.section << ',' << r.n << ',' << r.drum_radius << ',' << r.drum_speed << ',' << r.dt
      << ',' << r.steps << ',' << r.wall << ',' << r.cpu << ',' << r.rate_cpu() << ','
      << r.rate_wall() << ',' << r.ns_cpu() << ',' << r.ns_wall() << ',' << r.contacts_per_particle
      << ',' << r.neighbor_builds << ',' << r.settle_wall << ',' << r.settle_time << ','
      << (r.section == "block" ? kTargetBlock : kTargetRate) << ',' << r.ratio << ',' << r.repeats
      << ',' << r.cpu_max << ',' << r.candidates_per_particle << ',' << r.rss_per_particle << ','
      << r.store_per_particle << ',' << r.pairs_per_particle << ',' << r.cost_vs_mono << ','
      << r.pair_contacts_per_particle << ',' << r.ids << ',' << sort_name(r.sort) << ',' << r.sorts
      << '\n';
}

// Each size with its ids as filled and shuffled, the store in id order and as "auto" chooses.
void order_section(const Options& opt, std::vector<Row>& rows) {
  std::printf("\n== storage order: ids as filled or shuffled; run.spatial_sort never / auto\n");
  for (std::int64_t n : opt.order_particles) {
    const bench::Packing pk =
        opt.cache ? bench::settled_packing(n, opt.results + "/cache") : bench::settle_packing(n);
    const auto nd = static_cast<double>(n);
    for (const char* ids : {"fill", "shuffled"}) {
      double never_ns = 0.0;
      for (dem2d::SpatialSort sort : {dem2d::SpatialSort::kNever, dem2d::SpatialSort::kAuto}) {
        Row row;
        row.section = "order";
        row.ratio = bench::kRadiusMax / bench::kRadiusMin;
        row.ids = ids;
        row.sort = sort;
        row.steps =
            std::min(std::max(opt.steps, static_cast<std::int64_t>(opt.min_particle_steps / nd)),
                     static_cast<std::int64_t>(opt.max_particle_steps / nd));
        try {
          row = measure_packing(opt, pk, 1.0e-6, row);
        } catch (const std::exception& e) {
          std::printf("N = %lld failed: %s\n", static_cast<long long>(n), e.what());
          continue;
        }
        if (sort == dem2d::SpatialSort::kNever) never_ns = row.ns_cpu();
        row.cost_vs_mono = never_ns > 0.0 ? row.ns_cpu() / never_ns : 0.0;
        print_row(row, settling_of(pk));
        std::printf("          ids %s, spatial_sort %s: %lld sorts; %.2f x the id-order cost\n",
                    ids, sort_name(sort), static_cast<long long>(row.sorts), row.cost_vs_mono);
        rows.push_back(row);
      }
    }
  }
}

void drum_section(const Options& opt, std::vector<Row>& rows) {
  const std::vector<Row> drum = measure_drums(opt, opt.particles, false);
  if (drum.empty()) return;
  const Row* a = &drum.back();
  for (const Row& r : drum)
    if (r.n == 30000) a = &r;
  std::printf(
      "(a) N = %lld: %.3e particle-steps/s by CPU time (%.3e by wall time) = %.0f %% of "
      "the target of 15e6/s\n",
      static_cast<long long>(a->n), a->rate_cpu(), a->rate_wall(),
      100.0 * a->rate_cpu() / kTargetRate);
  if (drum.size() >= 2) {
    const Row& lo = drum.front();
    const Row& hi = drum.back();
    const double slope = std::log(hi.ns_cpu() * static_cast<double>(hi.n) /
                                  (lo.ns_cpu() * static_cast<double>(lo.n))) /
                         std::log(static_cast<double>(hi.n) / static_cast<double>(lo.n));
    std::printf(
        "(b) cost per step grows as N^%.3f between N = %lld and %lld (1 = linear); ns per "
        "particle-step %.1f -> %.1f; resident memory %.0f -> %.0f bytes per particle\n",
        slope, static_cast<long long>(lo.n), static_cast<long long>(hi.n), lo.ns_cpu(), hi.ns_cpu(),
        lo.rss_per_particle, hi.rss_per_particle);
  }
  rows.insert(rows.end(), drum.begin(), drum.end());
}

void deposited_section(const Options& opt, std::vector<Row>& rows) {
  const std::vector<Row> dep = measure_drums(opt, opt.deposited, true);
  const Row* base = nullptr;
  for (const Row& r : dep)
    if (r.n == 10000) base = &r;
  if (base)
    for (const Row& r : dep)
      std::printf(
          "(d) deposited N = %lld: %.1f ns per particle-step = %.2f x the 1e4 bed's %.1f ns "
          "(bound: <= 1.3 x); %.2f contacts and %.2f candidates per particle, %.0f "
          "bytes of memory per particle\n",
          static_cast<long long>(r.n), r.ns_cpu(), r.ns_cpu() / base->ns_cpu(), base->ns_cpu(),
          r.contacts_per_particle, r.candidates_per_particle, r.rss_per_particle);
  rows.insert(rows.end(), dep.begin(), dep.end());
}

void ratio_section(const Options& opt, std::vector<Row>& rows) {
  std::vector<Row> rat;
  for (double ratio : opt.ratios) {
    try {
      rat.push_back(measure_ratio(opt, ratio));
    } catch (const std::exception& e) {
      std::printf("size ratio %g failed: %s\n", ratio, e.what());
    }
  }
  const Row* mono = nullptr;
  for (const Row& r : rat)
    if (r.ratio == 1.0) mono = &r;
  if (mono) {
    const double base = mono->ns_cpu();
    for (Row& r : rat) r.cost_vs_mono = r.ns_cpu() / base;
    for (const Row& r : rat)
      std::printf(
          "(r) size ratio %g: %.1f ns per particle-step = %.2f x the monodisperse %.1f "
          "ns%s\n",
          r.ratio, r.ns_cpu(), r.cost_vs_mono, base, r.ratio == 10.0 ? " (bound: <= 1.5 x)" : "");
  }
  rows.insert(rows.end(), rat.begin(), rat.end());
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  if (!opt.profile.empty()) return run_profile(opt);
  const Stopwatch total;
  std::filesystem::create_directories(opt.results);
  std::printf("== throughput: sections");
  for (const std::string& s : opt.sections) std::printf(" %s", s.c_str());
  std::printf(
      "\n   drum: polydisperse steel (r %g-%g mm), hertz-mindlin + epsd, circular drum, dt "
      "1e-6 s; target %.0f million particle-steps/s on one core = %.1f ns per "
      "particle-step\n\n",
      1e3 * bench::kRadiusMin, 1e3 * bench::kRadiusMax, kTargetRate / 1e6, 1e9 / kTargetRate);
  print_header();
  std::vector<Row> rows;
  if (opt.has("drum")) drum_section(opt, rows);
  if (opt.has("deposited")) deposited_section(opt, rows);
  if (opt.has("ratios")) ratio_section(opt, rows);
  if (opt.has("order")) order_section(opt, rows);
  if (opt.has("block")) {
    try {
      const Row b = measure_block(opt);
      std::printf(
          "(c) dense sliding block: %.3e particle-steps/s (CPU) = %.1f ns per "
          "particle-step, %.2f contacts per particle (%.2f particle-particle, the rest "
          "with the shell); target %.0f million/s\n",
          b.rate_cpu(), b.ns_cpu(), b.contacts_per_particle, b.pair_contacts_per_particle,
          kTargetBlock / 1e6);
      rows.push_back(b);
    } catch (const std::exception& e) {
      std::printf("block failed: %s\n", e.what());
    }
  }
  std::printf(
      "   (spread: slowest / fastest repeat - 1 by CPU; p-steps/s, ns/p-st: fastest repeat by CPU "
      "time, then by wall time; contac: particle-particle plus wall contacts per particle; "
      "candid:\n    listed pairs per particle; builds: neighbour rebuilds in the timed steps; B "
      "RSS / sto / pair: bytes per particle of resident memory growth, particle store, pair "
      "lists;\n    settling: wall time of the untimed settling, or 'cache')\n");
  if (opt.has("waterfall")) {
    std::printf("\n");
    const double duration = opt.quick ? 1.0 : 10.0;
    try {
      const Row w = measure_waterfall(duration);
      std::printf("(w) waterfall %.0f s: %.2f s wall, %.2f s CPU against the target of %.1f s%s\n",
                  duration, w.wall, w.cpu, kTargetWaterfall * duration / 10.0,
                  opt.quick ? " (the 5 s target scaled to 1 s)" : "");
      rows.push_back(w);
    } catch (const std::exception& e) {
      std::printf("waterfall failed: %s\n", e.what());
    }
  }
  const std::string csv = opt.results + "/" + opt.csv;
  write_csv(csv, rows);
  std::printf("wrote %s\n", csv.c_str());
  if (opt.plot) {
    const std::string png = csv.substr(0, csv.rfind('.')) + ".png";
    const std::string cmd = "/usr/bin/python3 " DEM2D_SOURCE_DIR "/post/plot_throughput.py '" +
                            csv + "' -o '" + png + "'";
    std::printf("$ %s\n", cmd.c_str());
    std::fflush(stdout);
    if (std::system(cmd.c_str()) != 0) std::printf("throughput: the plot script failed\n");
  }
  std::printf("throughput: total %.1f s wall, %.1f s CPU\n", total.wall(), total.cpu());
  return 0;
}
