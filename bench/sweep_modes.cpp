// sweep_modes: how many steps to sweep at once, measured so that the host's speed phases cancel.
//
// One process, one deposited bed (settled_drum.hpp, deposited_packing, as bench/throughput's
// deposited section: steel with e = 0.1 and mu_s = 0.5, the drum still, dt = 1e-6 s), stepped in
// blocks of --block-steps steps. The modes take the blocks in turn, the order rotated each round:
// mode 1 steps one step at a time, mode K sweeps up to K steps (Simulation::set_sweep_steps). All
// modes give the same bits (test_core PairedSteps.*), so they can share one run: every mode sees
// the same bed, and a slow minute of the host falls on neighbouring blocks of every mode alike.
// Mode 0 is the program's own timed choice (core/sweep_choice.hpp), which keeps its state from
// block to block: with it in the list every mode steps its own copy of the bed instead.
// Each block's thread CPU time per particle-step is compared with the first mode's block of the
// same round; the table gives the median of those ratios and its quartiles. Runs in separate
// processes moved by up to 20 % from one to the next on this machine (docs/performance.md), which
// hid the 5-8 % this resolves.
//
//   sweep_modes [--particles N] [--modes 1,4,8] [--rounds R] [--block-steps S]
//               [--results DIR] [--csv NAME] [--no-plot]
//
// Defaults: N = 100000, modes 1,4,8, 20 rounds, S = 1.6e6 / N rounded up to a multiple of 8 (at
// least 8). Writes DIR/NAME (default bench/results/sweep_modes.csv: round, mode, ns per
// particle-step, ratio to the first mode) and a box plot beside it (post/plot_sweep_modes.py).
// The bed must be in DIR/cache or is deposited and loaded first (minutes at 1e5, an hour at 1e6).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "blocks.hpp"
#include "core/simulation.hpp"
#include "lists.hpp"
#include "settled_drum.hpp"

namespace {

struct Options {
  std::int64_t n = 100000;
  std::vector<int> modes = {1, 4, 8};
  int rounds = 20;
  int block_steps = 0;  // 0: from n
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
  std::string csv = "sweep_modes.csv";
  bool plot = true;
};

int usage() {
  std::fprintf(stderr,
               "usage: sweep_modes [--particles N] [--modes 1,4,8] [--rounds R] [--block-steps S]\n"
               "                   [--results DIR] [--csv NAME] [--no-plot]\n");
  return 2;
}

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
        o.n = std::stoll(value());
      else if (a == "--modes")
        o.modes = bench::parse_list<int>(value());
      else if (a == "--rounds")
        o.rounds = std::stoi(value());
      else if (a == "--block-steps")
        o.block_steps = std::stoi(value());
      else if (a == "--results")
        o.results = value();
      else if (a == "--csv")
        o.csv = value();
      else if (a == "--no-plot")
        o.plot = false;
      else
        return usage();
    }
    for (const int m : o.modes)
      if (m < 0 || m > dem2d::kMaxSweepSteps)
        throw std::invalid_argument("--modes: 0 to " + std::to_string(dem2d::kMaxSweepSteps));
    if (o.n < 100 || o.rounds < 2 || o.modes.empty() || o.block_steps < 0)
      throw std::invalid_argument("--particles >= 100, --rounds >= 2, --block-steps >= 0");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_modes: %s\n", e.what());
    return usage();
  }
  if (o.block_steps == 0)
    o.block_steps = std::max<int>(8, static_cast<int>((1600000 / o.n + 7) / 8 * 8));

  // Mode 0, the program's timed choice, keeps its state from block to block: with it every mode
  // steps its own copy of the bed (all copies hold the same bits after each round).
  const bool own_beds = std::find(o.modes.begin(), o.modes.end(), 0) != o.modes.end();
  const std::size_t nm = o.modes.size();
  std::vector<std::unique_ptr<dem2d::Simulation>> sims;
  for (std::size_t m = 0; m < (own_beds ? nm : 1); ++m) {
    sims.push_back(bench::still_bed(o.n, o.results));
  }
  const auto set_mode = [&](dem2d::Simulation& sim, int mode) {
    if (mode == 1) {
      sim.set_pair_steps_from(static_cast<std::size_t>(1) << 40);
    } else if (mode > 1) {
      sim.set_pair_steps_from(0);
      sim.set_sweep_steps(mode);
    }  // 0: as constructed
  };
  if (own_beds)
    for (std::size_t m = 0; m < nm; ++m) set_mode(*sims[m], o.modes[m]);

  std::vector<std::vector<double>> ns(nm);
  const auto n = static_cast<double>(o.n);
  for (int r = 0; r < o.rounds; ++r) {
    for (std::size_t q = 0; q < nm; ++q) {
      const std::size_t m = (q + static_cast<std::size_t>(r)) % nm;
      dem2d::Simulation& sim = own_beds ? *sims[m] : *sims[0];
      if (!own_beds) set_mode(sim, o.modes[m]);
      const double t0 = bench::thread_cpu_seconds();
      for (int k = 0; k < o.block_steps;)
        k += sim.advance([&](int j) { return k + j == o.block_steps; });
      ns[m].push_back(1e9 * (bench::thread_cpu_seconds() - t0) / (n * o.block_steps));
    }
  }

  std::printf(
      "sweep_modes: %lld particles (deposited bed, %.2f contacts per particle), %d rounds "
      "of %d-step blocks per mode\n",
      static_cast<long long>(o.n), static_cast<double>(sims[0]->last_totals().contacts) / n,
      o.rounds, o.block_steps);
  std::printf("%-6s %10s %10s   over mode %d in its round: median (quartiles)\n", "mode",
              "ns median", "ns min", o.modes[0]);
  const std::string path = o.results + "/" + o.csv;
  std::ofstream csv(path);
  csv << "n_particles,mode,round,ns_per_particle_step_cpu,over_first_mode\n";
  for (std::size_t m = 0; m < nm; ++m) {
    std::vector<double> ratio;
    for (int r = 0; r < o.rounds; ++r) {
      const auto u = static_cast<std::size_t>(r);
      ratio.push_back(ns[m][u] / ns[0][u]);
      csv << o.n << ',' << o.modes[m] << ',' << r + 1 << ',' << ns[m][u] << ',' << ratio.back()
          << '\n';
    }
    std::printf("%-6d %10.2f %10.2f   %.3f (%.3f-%.3f)\n", o.modes[m], bench::quantile(ns[m], 0.5),
                bench::quantile(ns[m], 0.0), bench::quantile(ratio, 0.5),
                bench::quantile(ratio, 0.25), bench::quantile(ratio, 0.75));
  }
  csv.close();
  std::printf(
      "(mode 1: one step at a time; K: sweeps of up to K steps; 0: the program's timed choice; "
      "ns: thread CPU time per particle-step)\nwrote %s\n",
      path.c_str());
  for (std::size_t m = 0; m < nm; ++m)
    if (own_beds && o.modes[m] == 0 && sims[m]->sweep_choice())
      std::printf("mode 0: %lld trials, %lld chose sweeps\n",
                  static_cast<long long>(sims[m]->sweep_choice()->decisions()),
                  static_cast<long long>(sims[m]->sweep_choice()->trials_for_sweeps()));
  if (o.plot) bench::plot_beside("plot_sweep_modes.py", path);
  return 0;
}
