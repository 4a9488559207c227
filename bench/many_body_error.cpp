// many_body_error: errors that converge with dt on many bodies, against work, for both
// integrators (issue: honest numbers; complements bench/work_precision, whose waterfall panels
// compare time averages that lie inside the chaotic spread between seeds).
//
// Two scenes, each from its initial fill (same seed, same state):
//   waterfall   inputs/waterfall.in (240 balls, r = 0.1 m, 16-gon drum, 1.8 rad/s after 0.5 s);
//   polydisperse the same drum and speed with 240 balls of radius 0.05-0.1 m.
// For each integrator and dt = dt_auto x {1/4, 1/2, 1} (on one time grid, so that the runs are
// compared at the same instant):
//   trajectory  the RMS distance, over the particles matched by id, between this run and a
//               Verlet run at dt_auto / 16, a short time after the first contact (--horizon,
//               default 0.05 s; the charge falls from its fill first), before the runs part by
//               chaos, on the common time grid; in ball radii;
//   ledger      (kinetic + rotational + potential + elastic + dissipated - drive work) at 1 s
//               minus at the start, over the drive work (the energy balance's residual);
//   spectrum    the collision energies breakage models read: every contact that ends within the
//               1 s gives its peak normal strain energy (the peak-energy tracker slot); the
//               error is the largest relative difference of the 50th, 90th and 99th
//               percentiles from those of a Verlet run at dt_auto / 16 over the same second;
//   work        force evaluations (steps x passes) and seconds spent stepping (wall time on one
//               core, the collision log excluded) per simulated second.
// The trajectory error against work is the speed-against-error a user pays for; the ratio per
// halving of dt shows the order. Output: the table on stdout, bench/results/many_body_error.csv,
// bench/results/many_body_error.png (post/plot_many_body_error.py; --no-plot skips it).
//
//   many_body_error [--quick] [--no-plot] [--results DIR]
//
// --quick: the waterfall only, dt_auto x {1/2, 1}, the reference at dt_auto / 4.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "core/simulation.hpp"
#include "io/deck.hpp"

namespace dem2d {
namespace {

double g_horizon = 0.05;       // s after the first contact: trajectory comparison (--horizon)
double g_horizon_steps = 0.0;  // the horizon in steps of dt_auto
double g_dt_auto = 0.0;
constexpr double kLedgerTime = 1.0;

Scene scene_of(const std::string& name) {
  Scene s = load_deck(DEM2D_SOURCE_DIR "/inputs/waterfall.in");
  if (name == "polydisperse") {
    s.fills[0].radius_min = 0.05;
    s.fills[0].radius_max = 0.1;
  }
  s.output.snapshot_interval = 0.0;
  return s;
}

struct Run {
  std::map<std::int64_t, Vec2> at_horizon;  // positions by id
  std::vector<double> collisions;           // peak strain energy of every contact that ended (J)
  double mean_radius = 0.0;
  double residual = 0.0;                // balance residual / drive work at kLedgerTime
  double evaluations = 0.0, cpu = 0.0;  // per simulated second
};

// The contacts that ended since the last call give their peak energies (slot `slot`).
class CollisionLog {
 public:
  explicit CollisionLog(std::size_t slot) : slot_(slot) {}
  void after_step(const Simulation& sim, std::vector<double>& out) {
    const HistoryRecords r = sim.contacts().records();
    std::map<std::pair<std::int64_t, std::int64_t>, double> now;
    for (std::size_t k = 0; k < r.size(); ++k) now[{r.a(k), r.b(k)}] = r.values(k)[slot_];
    for (const auto& [key, peak] : live_)
      if (!now.contains(key)) out.push_back(peak);
    live_.swap(now);
  }

 private:
  std::size_t slot_;
  std::map<std::pair<std::int64_t, std::int64_t>, double> live_;
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
  for (long long k = 0; k < steps; ++k) timed_step();
  const ParticleStore& p = sim.particles();
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    out.at_horizon[p.id[k]] = p.pos[k];
    out.mean_radius += p.radius[k] / static_cast<double>(p.n_owned());
  }
  const double t_end = ledger ? kLedgerTime : g_horizon_steps * g_dt_auto;
  CollisionLog log(peak_slot(sim));
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

double rms_distance(const Run& a, const Run& ref) {
  double sum = 0.0;
  for (const auto& [id, x] : a.at_horizon) sum += norm2(x - ref.at_horizon.at(id));
  return std::sqrt(sum / static_cast<double>(a.at_horizon.size())) / ref.mean_radius;
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
         "spectrum_error,collisions,evaluations_per_s,step_seconds_per_s\n";
  std::printf("%-13s %-10s %10s %8s %12s %6s %11s %9s %6s %10s %8s\n", "scene", "integrator",
              "dt_s", "dt/auto", "traj_err_r", "order", "ledger_res", "spectrum", "coll", "evals/s",
              "step_s/s");
  const std::vector<std::string> scenes =
      quick ? std::vector<std::string>{"waterfall"}
            : std::vector<std::string>{"waterfall", "polydisperse"};
  for (const std::string& name : scenes) {
    const Scene base = scene_of(name);
    Scene probe = base;
    probe.run.dt_auto = true;
    const double dt_auto = Simulation(probe).dt();
    g_dt_auto = dt_auto;
    // The horizon: g_horizon after the first contact (the charge falls from its fill first), on
    // the common grid of every dt (dt_auto / 16 divides them all).
    double touch = 0.0;
    {
      Scene at = base;
      at.run.dt_auto = true;
      Simulation sim(at);
      while (sim.last_totals().contacts == 0 && sim.time() < 1.0) sim.step();
      touch = sim.time();
    }
    g_horizon_steps = std::max(1.0, std::round((touch + g_horizon) / dt_auto));
    const Run ref = run(base, IntegratorKind::kVerlet, dt_auto / (quick ? 4.0 : 16.0), true);
    std::vector<double> factors =
        quick ? std::vector<double>{0.5, 1.0} : std::vector<double>{0.25, 0.5, 1.0};
    for (const IntegratorKind integ : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
      const char* iname = integ == IntegratorKind::kVerlet ? "verlet" : "iterative";
      double previous = 0.0;
      for (const double f : factors) {
        const double dt = f * dt_auto;
        std::string order = "";
        Run r;
        try {
          r = run(base, integ, dt, true);
        } catch (const UnstableError& e) {
          std::printf("%-13s %-10s %10.4g %8.3g  exit 3: %.60s\n", name.c_str(), iname, dt, f,
                      e.what());
          continue;
        }
        const double err = rms_distance(r, ref);
        if (previous > 0.0) {
          char b[16];
          std::snprintf(b, sizeof b, "%.2f", err / previous);
          order = b;
        }
        previous = err;
        const bool is_auto = f == 1.0;
        const double spectrum = spectrum_error(r.collisions, ref.collisions);
        std::printf("%-13s %-10s %10.4g %8.3g %12.4g %6s %11.3g %9.3g %6zu %10.4g %8.4g%s\n",
                    name.c_str(), iname, dt, f, err, order.c_str(), r.residual, spectrum,
                    r.collisions.size(), r.evaluations, r.cpu, is_auto ? "  <- dt = \"auto\"" : "");
        std::fflush(stdout);
        csv << name << "," << iname << "," << dt << "," << f << "," << (is_auto ? 1 : 0) << ","
            << err << "," << r.residual << "," << spectrum << "," << r.collisions.size() << ","
            << r.evaluations << "," << r.cpu << "\n";
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
