// many_body_error: errors that converge with dt on many bodies, against work, for both
// integrators (issue: honest numbers; complements bench/work_precision, whose waterfall panels
// compare time averages that lie inside the chaotic spread between seeds).
//
// Two scenes, each from its initial fill (8 seeds, 8 fills; 3 with --quick):
//   waterfall   inputs/waterfall_polygon.in (240 balls, r = 0.1 m, 16-gon drum, 1.8 rad/s after 0.5
//   s); polydisperse the same drum and speed with 240 balls of radius 0.05-0.1 m.
// For each integrator and dt = dt_auto x {1/4, 1/2, 1} (on one time grid, so that the runs are
// compared at the same instant):
//   trajectory  the RMS distance, over the particles matched by id, between this run and a
//               Verlet run at dt_auto / 16, a short time after the first contact (--horizon,
//               default 0.05 s; the charge falls from its fill first), before the runs part by
//               chaos, on the common time grid; in ball radii, RMS over every seed;
//   ledger      (seed 1) (kinetic + rotational + potential + elastic + dissipated - drive work) at
//   1 s
//               minus at the start, over the drive work (the energy balance's residual);
//   collisions  the collision energies breakage models read: every contact that ends gives its
//               peak normal strain energy (the peak-energy tracker slot).
//               early: the contacts that end before the horizon, over every seed, matched with
//               the reference's by (pair ids, occurrence); the median of |E / E_ref - 1| over
//               the matched ones, and sum |E - E_ref| / sum E_ref over the union (a contact in
//               one run only counts in full, so a rattle that splits one touch in two shows).
//               These converge with dt while the trajectories do.
//               1 s (seed 1 only): the largest relative difference of the 50th, 90th and 99th
//               percentiles of every contact ending within 1 s, against the reference's: a
//               statistic of runs that have parted by chaos, so it measures their spread, not the
//               step;
//   work        (seed 1) force evaluations (steps x passes) and seconds spent stepping (wall time
//   on one
//               core, the collision log excluded) per simulated second.
// The trajectory error against work is the speed-against-error a user pays for; the ratio per
// halving of dt shows the order. Output: the table on stdout, bench/results/many_body_error.csv,
// bench/results/many_body_error.png (post/plot_many_body_error.py; --no-plot skips it).
//
//   many_body_error [--quick] [--no-plot] [--results DIR]
//
// --quick: the waterfall only, 3 seeds, dt_auto x {1/2, 1}, the reference at dt_auto / 4.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/base/errors.hpp"
#include "core/run/simulation.hpp"
#include "io/deck.hpp"

namespace dem2d {
namespace {

double g_horizon = 0.05;       // s after the first contact: trajectory comparison (--horizon)
double g_horizon_steps = 0.0;  // the horizon in steps of dt_auto
double g_dt_auto = 0.0;
constexpr double kLedgerTime = 1.0;

Scene scene_of(const std::string& name) {
  Scene s = load_deck(DEM2D_SOURCE_DIR "/inputs/waterfall_polygon.in");
  if (name == "polydisperse") {
    s.fills[0].radius_min = 0.05;
    s.fills[0].radius_max = 0.1;
  }
  s.output.snapshot_interval = 0.0;
  return s;
}

// A contact's identity across runs: its pair of ids and which contact of that pair it is.
using CollisionKey = std::tuple<std::int64_t, std::int64_t, int>;

struct Run {
  std::map<std::int64_t, Vec2> at_horizon;  // positions by id
  std::vector<double> collisions;           // peak strain energy of every contact that ended (J)
  std::map<CollisionKey, double> early;     // the same, keyed, for contacts ended by the horizon
  double mean_radius = 0.0;
  double residual = 0.0;                // balance residual / drive work at kLedgerTime
  double evaluations = 0.0, cpu = 0.0;  // per simulated second
};

// The contacts that ended since the last call give their peak energies (slot `slot`).
class CollisionLog {
 public:
  explicit CollisionLog(std::size_t slot) : slot_(slot) {}
  void after_step(const Simulation& sim, std::vector<double>& out,
                  std::map<CollisionKey, double>* keyed = nullptr) {
    const HistoryRecords r = sim.contacts().records();
    std::map<std::pair<std::int64_t, std::int64_t>, double> now;
    for (std::size_t k = 0; k < r.size(); ++k) now[{r.a(k), r.b(k)}] = r.values(k)[slot_];
    for (const auto& [key, peak] : live_) {
      if (now.contains(key)) continue;
      out.push_back(peak);
      if (keyed) (*keyed)[{key.first, key.second, ended_[key]++}] = peak;
    }
    live_.swap(now);
  }

 private:
  std::size_t slot_;
  std::map<std::pair<std::int64_t, std::int64_t>, double> live_;
  std::map<std::pair<std::int64_t, std::int64_t>, int> ended_;  // contacts ended, per pair
};

std::size_t peak_slot(const Simulation& sim) {
  const auto slots = sim.contacts().history_slots();
  for (std::size_t k = 0; k < slots.size(); ++k)
    if (std::string(slots[k].name) == "peak_energy") return k;
  return 0;
}

Run run(const Scene& base, IntegratorKind integrator, double dt, bool ledger) {
  Scene s = base;
  s.contact.track_peak_energy = true;  // a history slot only: no particle state changes
  s.run.integrator = integrator;
  s.run.dt_auto = false;
  s.run.dt = dt;
  s.run.allow_unsafe_dt = true;
  Simulation sim(s);
  const auto balance = [](const SeriesRow& r) {
    return r.kinetic_energy + r.rotational_energy + r.potential_energy + r.elastic_energy +
           r.dissipated_energy - r.drive_work;
  };
  const double b0 = balance(sim.diagnostics());
  Run out;
  // Time in the steps only (not in the collision log): wall time on one core.
  double stepping = 0.0;
  const auto timed_step = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    sim.step();
    stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const long long steps = std::llround(g_horizon_steps * g_dt_auto / dt);
  CollisionLog log(peak_slot(sim));
  for (long long k = 0; k < steps; ++k) {
    timed_step();
    log.after_step(sim, out.collisions, &out.early);
  }
  const ParticleStore& p = sim.particles();
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    out.at_horizon[p.id[k]] = p.pos[k];
    out.mean_radius += p.radius[k] / static_cast<double>(p.n_owned());
  }
  const double t_end = ledger ? kLedgerTime : g_horizon_steps * g_dt_auto;
  while (sim.time() + 0.5 * sim.dt() < t_end) {
    timed_step();
    if (ledger) log.after_step(sim, out.collisions);
  }
  out.cpu = stepping / t_end;
  out.evaluations = static_cast<double>(sim.passes_total()) / t_end;
  const SeriesRow r = sim.diagnostics();
  out.residual = ledger ? (balance(r) - b0) / r.drive_work : 0.0;
  return out;
}

// The largest relative difference of the 50th, 90th and 99th percentiles of the collision
// energies.
double spectrum_error(std::vector<double> a, std::vector<double> ref) {
  if (a.empty() || ref.empty()) return 0.0;
  std::sort(a.begin(), a.end());
  std::sort(ref.begin(), ref.end());
  double worst = 0.0;
  for (const double q : {0.5, 0.9, 0.99}) {
    const double x = a[static_cast<std::size_t>(q * static_cast<double>(a.size() - 1))];
    const double y = ref[static_cast<std::size_t>(q * static_cast<double>(ref.size() - 1))];
    worst = std::max(worst, std::abs(x / y - 1.0));
  }
  return worst;
}

// The errors summed over seeds: squared distances (in radii) and |E - E_ref| over E_ref.
struct ErrorSums {
  double distance2 = 0.0, diff = 0.0, total = 0.0;
  std::size_t particles = 0, early_count = 0;
  std::vector<double> relative;  // |E / E_ref - 1| of the matched contacts
  void add(const Run& a, const Run& ref) {
    double d2 = 0.0;
    for (const auto& [id, x] : a.at_horizon) d2 += norm2(x - ref.at_horizon.at(id));
    distance2 += d2 / (ref.mean_radius * ref.mean_radius);
    particles += a.at_horizon.size();
    for (const auto& [key, e] : ref.early) {
      total += e;
      const auto it = a.early.find(key);
      diff += std::abs((it == a.early.end() ? 0.0 : it->second) - e);
      if (it != a.early.end()) relative.push_back(std::abs(it->second / e - 1.0));
    }
    for (const auto& [key, e] : a.early)
      if (!ref.early.contains(key)) diff += e;
    early_count += ref.early.size();
  }
  double median() const {
    std::vector<double> r = relative;
    if (r.empty()) return 0.0;
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    return r[r.size() / 2];
  }
  double trajectory() const { return std::sqrt(distance2 / static_cast<double>(particles)); }
  double early() const { return total > 0.0 ? diff / total : 0.0; }
};

std::string ratio(double x, double previous) {
  if (previous <= 0.0) return "";
  char b[16];
  std::snprintf(b, sizeof b, "%.2f", x / previous);
  return b;
}

// The horizon: g_horizon after the first contact (the charge falls from its fill first), on
// the common grid of every dt (dt_auto / 16 divides them all).
void set_horizon(const Scene& scene) {
  Scene at = scene;
  at.run.dt_auto = true;
  Simulation sim(at);
  while (sim.last_totals().contacts == 0 && sim.time() < 1.0) sim.step();
  g_horizon_steps = std::max(1.0, std::round((sim.time() + g_horizon) / g_dt_auto));
}

}  // namespace
}  // namespace dem2d

int main(int argc, char** argv) {
  using namespace dem2d;
  bool quick = false, plot = true;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--no-plot") {
      plot = false;
    } else if (a == "--results" && i + 1 < argc) {
      results = argv[++i];
    } else if (a == "--horizon" && i + 1 < argc) {
      g_horizon = std::stod(argv[++i]);
    } else {
      std::fprintf(stderr,
                   "usage: many_body_error [--quick] [--horizon T] [--no-plot] [--results DIR]\n");
      return 2;
    }
  }
  std::filesystem::create_directories(results);
  const std::string csv_path = results + "/many_body_error.csv";
  std::ofstream csv(csv_path);
  csv << "scene,integrator,dt,dt_over_auto,is_auto,trajectory_error_radii,ledger_residual,"
         "early_collision_error,early_collisions,early_collision_median,spectrum_error,collisions,"
         "evaluations_per_s,"
         "step_seconds_per_s\n";
  std::printf("%-13s %-10s %10s %8s %12s %6s %11s %9s %6s %6s %9s %9s %6s %10s %8s\n", "scene",
              "integrator", "dt_s", "dt/auto", "traj_err_r", "order", "ledger_res", "early_E",
              "order", "n", "median_E", "pctl_1s", "coll", "evals/s", "step_s/s");
  const std::vector<std::string> scenes =
      quick ? std::vector<std::string>{"waterfall"}
            : std::vector<std::string>{"waterfall", "polydisperse"};
  const int n_seeds = quick ? 3 : 8;
  for (const std::string& name : scenes) {
    const Scene base = scene_of(name);
    Scene probe = base;
    probe.run.dt_auto = true;
    g_dt_auto = Simulation(probe).dt();
    const std::vector<double> factors =
        quick ? std::vector<double>{0.5, 1.0} : std::vector<double>{0.25, 0.5, 1.0};
    const double ref_dt = g_dt_auto / (quick ? 4.0 : 16.0);
    // Seed 1 runs the whole second (ledger, 1 s spectrum, work); every seed (a different fill)
    // runs to its horizon and adds to the trajectory and early-collision errors.
    std::map<std::pair<int, double>, Run> first;  // (integrator, factor) -> seed 1's run
    std::map<std::pair<int, double>, ErrorSums> sums;
    std::map<std::pair<int, double>, std::string> failed;
    Run ref_first;
    for (int seed = 1; seed <= n_seeds; ++seed) {
      Scene sc = base;
      sc.run.seed = static_cast<std::uint64_t>(seed);
      set_horizon(sc);
      const bool whole = seed == 1;
      const Run ref = run(sc, IntegratorKind::kVerlet, ref_dt, whole);
      if (whole) ref_first = ref;
      for (const IntegratorKind integ : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
        for (const double f : factors) {
          const std::pair<int, double> key{static_cast<int>(integ), f};
          if (failed.contains(key)) continue;
          try {
            Run r = run(sc, integ, f * g_dt_auto, whole);
            sums[key].add(r, ref);
            if (whole) first[key] = std::move(r);
          } catch (const UnstableError& e) {
            failed[key] = e.what();
          }
        }
      }
    }
    for (const IntegratorKind integ : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
      const char* iname = integ == IntegratorKind::kVerlet ? "verlet" : "iterative";
      double previous = 0.0, previous_early = 0.0;
      for (const double f : factors) {
        const double dt = f * g_dt_auto;
        const std::pair<int, double> key{static_cast<int>(integ), f};
        if (failed.contains(key)) {
          std::printf("%-13s %-10s %10.4g %8.3g  exit 3: %.60s\n", name.c_str(), iname, dt, f,
                      failed[key].c_str());
          continue;
        }
        const Run& r = first[key];
        const ErrorSums& e = sums[key];
        const double err = e.trajectory(), early = e.early();
        const std::string order = ratio(err, previous), early_order = ratio(early, previous_early);
        previous = err;
        previous_early = early;
        const bool is_auto = f == 1.0;
        const double spectrum = spectrum_error(r.collisions, ref_first.collisions);
        std::printf(
            "%-13s %-10s %10.4g %8.3g %12.4g %6s %11.3g %9.3g %6s %6zu %9.3g %9.3g %6zu %10.4g "
            "%8.4g%s\n",
            name.c_str(), iname, dt, f, err, order.c_str(), r.residual, early, early_order.c_str(),
            e.relative.size(), e.median(), spectrum, r.collisions.size(), r.evaluations, r.cpu,
            is_auto ? "  <- dt = \"auto\"" : "");
        std::fflush(stdout);
        csv << name << "," << iname << "," << dt << "," << f << "," << (is_auto ? 1 : 0) << ","
            << err << "," << r.residual << "," << early << "," << e.relative.size() << ","
            << e.median() << "," << spectrum << "," << r.collisions.size() << "," << r.evaluations
            << "," << r.cpu << "\n";
      }
    }
  }
  csv.close();  // the plot script reads it
  std::printf("wrote %s\n", csv_path.c_str());
  if (plot) {
    const std::string cmd = "/usr/bin/python3 " DEM2D_SOURCE_DIR "/post/plot_many_body_error.py '" +
                            csv_path + "' -o '" + results + "/many_body_error.png'";
    if (std::system(cmd.c_str()) != 0) std::printf("many_body_error: the plot script failed\n");
  }
  return 0;
}
