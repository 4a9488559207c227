// grinding: what the ore models cost, and how exact their bookkeeping is (issue: grinding).
//
// inputs/grinding.in (120 steel balls + 60 ore, 1.5 rad/s, feed every 0.25 s, central sieve,
// breakage from 1 s) run on one core from its fill, four ways:
//   grinding        the deck as shipped: breakage, feed and sieve;
//   tests only      the deck with a strength of 1e-30 1/J: every contact is tracked and tested
//                   but nothing breaks, so the charge stays the one of the next row: the cost of
//                   the breakage model itself (tracker slots, the scan for tests);
//   no breakage     the same charge, feed and sieve, without [breakage] (its tracker is not
//                   compiled into the kernel the scene runs);
//   charge only     the same charge without [breakage], [feed] and [sieve] (the kernel and the
//                   step of a scene without ore models);
//   waterfall       inputs/waterfall_polygon.in, the thesis scene with no ore models.
// Each row: particle-steps per wall second over the steps (the steps only), the particles at
// the end, breakages, fed and discharged counts, and the two error measures: the mass balance
// (initial mill mass + fed - mill mass - discharged, over the mill mass, worst row) and the
// energy balance residual over the drive work at the end.
//
// --baseline OLD_DEM2D: the cost of the grinding code in a scene without ore models. The
// waterfall deck (3 s) is run by OLD_DEM2D (a binary built before the grinding code, e.g. from
// commit 048fec3 in a second work tree) and by this build's dem2d, alternately, --pairs times
// each; the table gives both wall times per pair and the median of the new/old ratios (the
// machine's drift cancels pair by pair). The two runs' snapshots are compared too.
//
//   grinding [--duration S] [--baseline OLD_DEM2D [--pairs N]] [--no-plot] [--results DIR]
//
// Writes the table, bench/results/grinding.csv and bench/results/grinding.png (a bar chart of the
// rates).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "io/deck.hpp"

namespace dem2d {
namespace {

struct Row {
  std::string name;
  double rate = 0.0;  // particle-steps per second
  std::int64_t particles = 0, breakages = 0, fed = 0, discharged = 0;
  double mass_error = 0.0, energy_residual = 0.0;
};

Row measure(const std::string& name, Scene scene, double duration) {
  scene.run.duration = duration;
  scene.output.snapshot_interval = 0.0;
  Simulation sim(scene);
  const SeriesRow first = sim.diagnostics();
  const double b0 = energy_balance(first);
  Row row;
  row.name = name;
  double seconds = 0.0, particle_steps = 0.0, worst = 0.0;
  const std::int64_t check_every = 1000;
  while (sim.time() + 0.5 * sim.dt() < duration) {
    const double n = static_cast<double>(sim.particles().n_owned());
    const auto t0 = std::chrono::steady_clock::now();
    sim.step();
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    particle_steps += n;
    if (sim.step_count() % check_every == 0 && sim.grinding()) {
      const SeriesRow r = sim.diagnostics();
      worst =
          std::max(worst, std::abs(first.mill_mass + r.fed_mass - r.mill_mass - r.discharged_mass) /
                              first.mill_mass);
    }
  }
  const SeriesRow r = sim.diagnostics();
  row.rate = particle_steps / seconds;
  row.particles = r.particles;
  row.breakages = r.breakages;
  row.fed = r.fed_count;
  row.discharged = r.discharged_count;
  row.mass_error = worst;
  row.energy_residual = (energy_balance(r) - b0) / r.drive_work;
  return row;
}

// Wall seconds of one shell command (its output discarded); negative when it failed.
double timed(const std::string& command) {
  const auto t0 = std::chrono::steady_clock::now();
  const int status = std::system((command + " > /dev/null 2>&1").c_str());
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return status == 0 ? s : -1.0;
}

// The waterfall by the old and the new binary, alternately; returns the median new/old ratio.
double baseline_ratio(const std::string& old_binary, int pairs, const std::string& results) {
  const std::string deck = DEM2D_SOURCE_DIR "/inputs/waterfall_polygon.in";
  const std::string args = " --quiet " + deck + " --set run.duration=3 --output ";
  const std::string new_binary = DEM2D_BINARY;
  std::vector<double> ratios;
  std::printf("waterfall 3 s, whole process: old binary %s, new %s\n", old_binary.c_str(),
              new_binary.c_str());
  std::printf("%5s %10s %10s %8s\n", "pair", "old_s", "new_s", "new/old");
  for (int k = 0; k < pairs; ++k) {
    std::filesystem::remove_all(results + "/baseline_old");  // one folder, one run
    const double t_old = timed(old_binary + args + results + "/baseline_old");
    std::filesystem::remove_all(results + "/baseline_new");
    const double t_new = timed(new_binary + args + results + "/baseline_new");
    if (t_old <= 0.0 || t_new <= 0.0) {
      std::printf("a run failed (old %g s, new %g s)\n", t_old, t_new);
      return 0.0;
    }
    ratios.push_back(t_new / t_old);
    std::printf("%5d %10.3f %10.3f %8.4f\n", k + 1, t_old, t_new, t_new / t_old);
  }
  std::sort(ratios.begin(), ratios.end());
  const double median = ratios[ratios.size() / 2];
  const int same =
      std::system(("/usr/bin/python3 " DEM2D_SOURCE_DIR "/post/h5compare.py " + results +
                   "/baseline_old/snapshots.h5 " + results + "/baseline_new/snapshots.h5")
                      .c_str());
  std::printf("median new/old %.4f (min %.4f, max %.4f)%s\n", median, ratios.front(), ratios.back(),
              same == 0 ? "" : "; the snapshots DIFFER");
  std::filesystem::remove_all(results + "/baseline_old");
  std::filesystem::remove_all(results + "/baseline_new");
  return median;
}

}  // namespace
}  // namespace dem2d

int main(int argc, char** argv) {
  using namespace dem2d;
  double duration = 4.0;
  bool plot = true;
  std::string baseline;
  int pairs = 8;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--duration" && i + 1 < argc) {
      duration = std::stod(argv[++i]);
    } else if (a == "--baseline" && i + 1 < argc) {
      baseline = argv[++i];
    } else if (a == "--pairs" && i + 1 < argc) {
      pairs = std::stoi(argv[++i]);
    } else if (a == "--no-plot") {
      plot = false;
    } else if (a == "--results" && i + 1 < argc) {
      results = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: grinding [--duration S] [--baseline OLD_DEM2D [--pairs N]] "
                   "[--no-plot] [--results DIR]\n");
      return 2;
    }
  }
  const Scene grinding = load_deck(DEM2D_SOURCE_DIR "/inputs/grinding.in");
  Scene tests_only = grinding;
  tests_only.breakage.strength = 1e-30;
  Scene no_breakage = grinding;
  no_breakage.breakage.present = false;
  Scene charge = no_breakage;
  charge.feed.present = false;
  charge.sieve.present = false;
  Scene waterfall = load_deck(DEM2D_SOURCE_DIR "/inputs/waterfall_polygon.in");
  std::vector<Row> rows;
  std::printf("%-13s %12s %9s %9s %5s %10s %12s %12s\n", "scene", "p-steps/s", "particles",
              "breakages", "fed", "discharged", "mass_error", "energy_res");
  for (const auto& [name, scene] :
       {std::pair{"grinding", grinding}, std::pair{"tests only", tests_only},
        std::pair{"no breakage", no_breakage}, std::pair{"charge only", charge},
        std::pair{"waterfall", waterfall}}) {
    const Row r = measure(name, scene, duration);
    std::printf("%-13s %12.4g %9lld %9lld %5lld %10lld %12.3g %12.3g\n", r.name.c_str(), r.rate,
                static_cast<long long>(r.particles), static_cast<long long>(r.breakages),
                static_cast<long long>(r.fed), static_cast<long long>(r.discharged), r.mass_error,
                r.energy_residual);
    std::fflush(stdout);
    rows.push_back(r);
  }
  std::filesystem::create_directories(results);
  const std::string csv_path = results + "/grinding.csv";
  {
    std::ofstream csv(csv_path);
    csv << "scene,particle_steps_per_s,particles,breakages,fed,discharged,mass_balance_error,"
           "energy_residual\n";
    for (const Row& r : rows)
      csv << r.name << "," << r.rate << "," << r.particles << "," << r.breakages << "," << r.fed
          << "," << r.discharged << "," << r.mass_error << "," << r.energy_residual << "\n";
  }
  std::printf("wrote %s\n", csv_path.c_str());
  if (!baseline.empty() && baseline_ratio(baseline, pairs, results) <= 0.0) return 1;
  if (plot) {
    const std::string cmd =
        "/usr/bin/python3 -c \"import csv,matplotlib;matplotlib.use('Agg');"
        "import matplotlib.pyplot as plt;r=list(csv.DictReader(open('" +
        csv_path +
        "')));f,a=plt.subplots(figsize=(7,3.5));"
        "a.barh([x['scene'] for x in r],[float(x['particle_steps_per_s'])/1e6 "
        "for x in r]);a.set_xlabel('million particle-steps per second (one "
        "core)');a.invert_yaxis();f.tight_layout();f.savefig('" +
        results + "/grinding.png',dpi=110)\"";
    if (std::system(cmd.c_str()) != 0)
      std::printf("grinding: the plot failed\n");
    else
      std::printf("wrote %s/grinding.png\n", results.c_str());
  }
  return 0;
}
