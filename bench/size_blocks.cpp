// size_blocks: the cost per particle-step against the charge's size (the bound: every size within
// 1.3x of the 1e4 cost), measured so that the host's speed phases cancel.
//
// One process holds the deposited beds of every size asked for (settled_drum.hpp,
// deposited_packing, as bench/throughput's deposited section: steel with e = 0.1 and mu_s = 0.5,
// the drum still, dt = 1e-6 s), each warmed by 50 steps, and steps them in blocks that take the
// sizes in turn, the order rotated each round. Each size steps as the program would (step(), the
// closing kick fused with the next drift but at the block's last step). A block is about --budget
// particle-steps (its steps a multiple of 8, at least 8), timed by the thread's CPU clock and
// compared with the first size's block of the same round: a slow minute of the host falls on
// neighbouring blocks of every size alike. bench/size_rounds.py runs each size as its own process
// instead, where the same binary moved by up to 20 % from one process to the next
// (docs/performance.md).
//
//   size_blocks [--particles 10000,30000,100000,300000,1000000] [--rounds R] [--budget P]
//               [--bound B] [--sort auto|always|never] [--results DIR] [--csv NAME] [--no-plot]
//
// Defaults: 20 rounds, P = 8e6, B = 1.3, --sort auto (run.spatial_sort of every bed). Writes
// DIR/NAME (default bench/results/size_blocks.csv: size, round, ns per particle-step, ratio to the
// first size) and a box plot beside it (post/plot_size_blocks.py). Beds not in DIR/cache are
// deposited and loaded first (minutes at 1e5, an hour at 1e6).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "blocks.hpp"
#include "core/run/simulation.hpp"
#include "lists.hpp"
#include "settled_drum.hpp"

namespace {

struct Options {
  std::vector<std::int64_t> sizes = {10000, 30000, 100000, 300000, 1000000};
  int rounds = 20;
  double budget = 8.0e6;
  double bound = 1.3;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
  std::string csv = "size_blocks.csv";
  bool plot = true;
  dem2d::SpatialSort sort = dem2d::SpatialSort::kAuto;  // run.spatial_sort of every bed
};

int usage() {
  std::fprintf(
      stderr,
      "usage: size_blocks [--particles N1,N2,...] [--rounds R] [--budget P] [--bound B]\n"
      "                   [--sort auto|always|never] [--results DIR] [--csv NAME] [--no-plot]\n");
  return 2;
}

// One size: its bed, stepped as the program steps, and its blocks' times.
struct Bed {
  std::int64_t n = 0;
  int block_steps = 0;
  std::unique_ptr<dem2d::Simulation> sim;
  std::vector<double> ns;  // per round: thread CPU ns per particle-step
  double contacts = 0.0;   // per particle, at the last block's end
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    for (int k = 1; k < argc; ++k) {
      const std::string a = argv[k];
      const auto value = [&]() -> std::string {
        if (k + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        return argv[++k];
      };
      if (a == "--particles")
        o.sizes = bench::parse_list<std::int64_t>(value());
      else if (a == "--rounds")
        o.rounds = std::stoi(value());
      else if (a == "--budget")
        o.budget = std::stod(value());
      else if (a == "--bound")
        o.bound = std::stod(value());
      else if (a == "--results")
        o.results = value();
      else if (a == "--csv")
        o.csv = value();
      else if (a == "--sort") {
        const std::string v = value();
        if (v == "auto")
          o.sort = dem2d::SpatialSort::kAuto;
        else if (v == "always")
          o.sort = dem2d::SpatialSort::kAlways;
        else if (v == "never")
          o.sort = dem2d::SpatialSort::kNever;
        else
          throw std::invalid_argument("--sort: auto, always or never");
      } else if (a == "--no-plot")
        o.plot = false;
      else
        return usage();
    }
    if (o.sizes.empty() || o.rounds < 2 || !(o.budget > 0.0) || !(o.bound > 1.0))
      throw std::invalid_argument(
          "--particles not empty, --rounds >= 2, --budget > 0, --bound > 1");
    for (const std::int64_t n : o.sizes)
      if (n < 100) throw std::invalid_argument("--particles: each at least 100");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "size_blocks: %s\n", e.what());
    return usage();
  }

  std::vector<Bed> beds;
  for (const std::int64_t n : o.sizes) {
    Bed b;
    b.n = n;
    const double steps = std::ceil(o.budget / static_cast<double>(n) / 8.0) * 8.0;
    b.block_steps = static_cast<int>(std::max(8.0, steps));
    b.sim = bench::still_bed(n, o.results, o.sort);
    beds.push_back(std::move(b));
  }

  const std::size_t nb = beds.size();
  for (int r = 0; r < o.rounds; ++r) {
    for (std::size_t q = 0; q < nb; ++q) {
      Bed& b = beds[(q + static_cast<std::size_t>(r)) % nb];
      dem2d::Simulation& sim = *b.sim;
      const double t0 = bench::thread_cpu_seconds();
      for (int k = 1; k <= b.block_steps; ++k) sim.step(/*end_observed=*/k == b.block_steps);
      b.ns.push_back(1e9 * (bench::thread_cpu_seconds() - t0) /
                     (static_cast<double>(b.n) * b.block_steps));
    }
  }
  for (Bed& b : beds)
    b.contacts = static_cast<double>(b.sim->last_totals().contacts) / static_cast<double>(b.n);

  std::printf("size_blocks: deposited beds, %d rounds of blocks of about %.3g particle-steps\n",
              o.rounds, o.budget);
  std::printf("%9s %7s %8s %8s %8s %9s %9s %9s   %s\n", "N", "steps", "contacts", "ns min",
              "ns q25", "ns median", "min/min1", "q25/q25_1",
              "over N1 in its round: median (quartiles), worst, rounds above the bound");
  const std::string path = o.results + "/" + o.csv;
  std::ofstream csv(path);
  csv << "n_particles,block_steps,round,ns_per_particle_step_cpu,over_first_size\n";
  int above_any = 0;
  for (const Bed& b : beds) {
    std::vector<double> ratio;
    int above = 0;
    for (int r = 0; r < o.rounds; ++r) {
      const auto u = static_cast<std::size_t>(r);
      ratio.push_back(b.ns[u] / beds[0].ns[u]);
      above += ratio.back() > o.bound ? 1 : 0;
      csv << b.n << ',' << b.block_steps << ',' << r + 1 << ',' << b.ns[u] << ',' << ratio.back()
          << '\n';
    }
    above_any += above;
    const auto q = [](const Bed& d, double at) { return bench::quantile(d.ns, at); };
    std::printf(
        "%9lld %7d %8.2f %8.2f %8.2f %9.2f %9.3f %9.3f   %.3f (%.3f-%.3f), %.3f, %d of %d\n",
        static_cast<long long>(b.n), b.block_steps, b.contacts, q(b, 0.0), q(b, 0.25), q(b, 0.5),
        q(b, 0.0) / q(beds[0], 0.0), q(b, 0.25) / q(beds[0], 0.25), bench::quantile(ratio, 0.5),
        bench::quantile(ratio, 0.25), bench::quantile(ratio, 0.75), bench::quantile(ratio, 1.0),
        above, o.rounds);
  }
  csv.close();
  std::printf(
      "(ns: thread CPU time per particle-step, over the rounds; min/min1 and q25/q25_1: the "
      "size's fastest block and lower quartile\n over the first size's; contacts: per particle "
      "at the end; N1 = %lld; every size within %.2gx of N1 in every round: %s)\nwrote %s\n",
      static_cast<long long>(beds[0].n), o.bound, above_any == 0 ? "yes" : "no", path.c_str());
  if (o.plot)
    bench::plot_beside("plot_size_blocks.py", path, " --bound " + std::to_string(o.bound));
  return 0;
}
