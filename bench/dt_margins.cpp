// dt_margins: how far above dt = "auto" each hard case keeps its physics (issue: honest numbers
// on hard cases).
//
// Each hard case of tests/scenes/test_hard_cases.cpp is built here again (the bench does not
// depend on test code) with its physical check, and run at dt = k x the auto dt for
// k = 1, 1.5, 2, 3, 4, 6, 8, 12, 16 (run.allow_unsafe_dt on), with both integrators where the
// case is cheap enough. A factor passes when the run ends without an instability (exit 3: an
// overlap beyond 0.25 of a radius, a particle moving more than 0.25 of its radius in a step,
// energy created, iterative passes far from settling, a non-finite state) and the case's check
// holds; the table gives the largest factor that passes before the first that fails, and why
// that one failed. The checks:
//   impact   1 mm steel spheres head-on at 2 x 25 m/s, e = 0.73: restitution within 1 %;
//   stack    ten steel balls (5 cm) on a floor, 0.5 s: at rest (< 1e-3 m/s), floor overlap
//            within 1 % of Hertz's;
//   corner   a ball in the shell-lifter corner of the thesis drum at 1.8 rad/s, carried, thrown
//            and caught for 2 s: reach < R + 5 % r;
//   pile     60 balls (4-6 cm) poured into a box, e = 0.05, 1 s: contained, balance residual
//            below 1 % of the dissipated energy;
//   range    400 balls of 1-10 cm in the 16-gon drum at 1.8 rad/s, 0.5 s: contained, overlap
//            below 5 % of the smaller radius, residual below 1 % of the drive work;
//   20000    20 000 balls (1 cm) in the 16-gon drum switched on at 10 rad/s, 20 ms (Verlet
//            only): contained, overlap below 5 %, residual below 1 % of the drive work.
// Output: the table on stdout, bench/results/dt_margins.csv, bench/results/dt_margins.png
// (post/plot_dt_margins.py through std::system; --no-plot skips it).
//
//   dt_margins [--quick] [--no-plot] [--results DIR]
//
// --quick: factors 1, 2, 4, 8 and the cheap cases only (a smoke test).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "settled_drum.hpp"

namespace dem2d {
namespace {

MaterialSpec steel(double restitution) {
  MaterialSpec m = bench::steel();  // thesis Table 1
  m.restitution = restitution;
  return m;
}

ParticleSpec ball(double r, Vec2 x, Vec2 v = {}) {
  ParticleSpec p;
  p.material = "steel";
  p.radius = r;
  p.position = x;
  p.velocity = v;
  return p;
}

WallSpec segment(Vec2 a, Vec2 b) {
  WallSpec w;
  w.from = a;
  w.to = b;
  w.material = "steel";
  return w;
}

Scene drum(int balls, double r_min, double r_max, double speed, double ramp) {
  Scene s;
  s.deck_path = "dt_margins";
  s.materials = {steel(0.73)};
  s.drum.present = true;
  s.drum.radius = 2.5;
  s.drum.speed = speed;
  s.drum.ramp_time = ramp;
  s.drum.sides = 16;
  s.drum.material = "steel";
  FillSpec f;
  f.material = "steel";
  f.count = balls;
  f.radius_min = r_min;
  f.radius_max = r_max;
  f.region = FillRegion::kBottom;
  s.fills = {f};
  return s;
}

double balance(const SeriesRow& r) {
  return r.kinetic_energy + r.rotational_energy + r.potential_energy + r.elastic_energy +
         r.dissipated_energy - r.drive_work;
}

// One run of a case: empty when its check holds, else why not.
using Check = std::function<std::string(Simulation&)>;

struct Case {
  std::string name;
  bool iterative_too;
  bool quick;
  std::function<Scene()> scene;
  Check run;
};

std::string fmt(const char* f, double x) {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::vector<Case> cases() {
  std::vector<Case> out;
  out.push_back({"impact", true, true,
                 [] {
                   Scene s;
                   s.deck_path = "dt_margins";
                   s.materials = {steel(0.73)};
                   s.run.gravity = {0.0, 0.0};
                   s.particles = {ball(0.5e-3, {-0.6e-3, 0.0}, {25.0, 0.0}),
                                  ball(0.5e-3, {0.6e-3, 0.0}, {-25.0, 0.0})};
                   return s;
                 },
                 [](Simulation& sim) -> std::string {
                   bool touched = false;
                   while (sim.time() < 1e-4 && !(touched && sim.last_totals().contacts == 0)) {
                     sim.step();
                     touched = touched || sim.last_totals().contacts > 0;
                   }
                   if (!touched || sim.last_totals().contacts != 0) return "no separation";
                   const double e = (sim.particles().vel[1].x - sim.particles().vel[0].x) / 50.0;
                   return std::abs(e - 0.73) < 0.01 * 0.73 ? "" : "restitution " + fmt("%.3f", e);
                 }});
  out.push_back({"stack", true, true,
                 [] {
                   Scene s;
                   s.deck_path = "dt_margins";
                   s.materials = {steel(0.73)};
                   s.walls = {segment({-1.0, 0.0}, {1.0, 0.0})};
                   for (int k = 0; k < 10; ++k)
                     s.particles.push_back(ball(0.05, {0.0, 0.05 + 0.1 * k}));
                   return s;
                 },
                 [](Simulation& sim) -> std::string {
                   sim.run_until(0.5);
                   const ParticleStore& p = sim.particles();
                   double v = 0.0, low = 1e9;
                   for (std::size_t k = 0; k < p.n_owned(); ++k) {
                     v = std::max(v, norm(p.vel[k]));
                     low = std::min(low, p.pos[k].y);
                   }
                   const double m = 4.0 / 3.0 * std::numbers::pi * 0.05 * 0.05 * 0.05 * 7800.0;
                   const double e_star = 2.0e11 / (2.0 * (1.0 - 0.25 * 0.25));
                   const double hertz = std::pow(
                       3.0 * 10.0 * m * 9.81 / (4.0 * e_star * std::sqrt(0.05)), 2.0 / 3.0);
                   if (v > 1e-3) return "not at rest: " + fmt("%.2g m/s", v);
                   const double overlap = 0.05 - low;
                   return std::abs(overlap / hertz - 1.0) < 0.01
                              ? ""
                              : "floor overlap " + fmt("%.3f", overlap / hertz) + " of Hertz";
                 }});
  out.push_back(
      {"corner", true, true,
       [] {
         Scene s = drum(0, 0.1, 0.1, 1.8, 0.0);
         s.fills.clear();
         s.drum.sides = 0;
         LifterSpec l;
         l.count = 4;
         l.height = 0.2;
         l.width = 0.1;
         l.angle = -std::numbers::pi / 2.0;  // the first lifter at the bottom
         s.drum.lifters = {l};
         // Touching the shell, just ahead of the lifter in the direction of turn.
         const double r = 0.1, R = 2.5;
         const double a = -std::numbers::pi / 2.0 + (0.05 + r + 1e-4) / R;
         s.particles = {ball(r, {(R - r - 1e-4) * std::cos(a), (R - r - 1e-4) * std::sin(a)})};
         return s;
       },
       [](Simulation& sim) -> std::string {
         double reach = 0.0;
         while (sim.time() < 2.0) {
           sim.step();
           const ParticleStore& p = sim.particles();
           reach = std::max(reach, norm(p.pos[0]) + p.radius[0]);
         }
         return reach < 2.5 + 0.005 ? "" : "reach " + fmt("%.4f m", reach);
       }});
  out.push_back({"pile", true, false,
                 [] {
                   Scene s;
                   s.deck_path = "dt_margins";
                   s.materials = {steel(0.05)};
                   s.walls = {segment({-0.6, 0.0}, {0.6, 0.0}), segment({-0.6, 0.0}, {-0.6, 1.5}),
                              segment({0.6, 0.0}, {0.6, 1.5})};
                   FillSpec f;
                   f.material = "steel";
                   f.count = 60;
                   f.radius_min = 0.04;
                   f.radius_max = 0.06;
                   f.region = FillRegion::kBox;
                   f.box_min = {-0.55, 0.3};
                   f.box_max = {0.55, 1.4};
                   s.fills = {f};
                   return s;
                 },
                 [](Simulation& sim) -> std::string {
                   const double b0 = balance(sim.diagnostics());
                   sim.run_until(1.0);
                   const SeriesRow r = sim.diagnostics();
                   const ParticleStore& p = sim.particles();
                   for (std::size_t k = 0; k < p.n_owned(); ++k)
                     if (std::abs(p.pos[k].x) > 0.6 || p.pos[k].y < 0.0) return "escaped";
                   const double res = (balance(r) - b0) / r.dissipated_energy;
                   return std::abs(res) < 0.01 ? "" : "residual " + fmt("%.3g", res);
                 }});
  const auto drum_check = [](double t_end) {
    return [t_end](Simulation& sim) -> std::string {
      const double b0 = balance(sim.diagnostics());
      double overlap = 0.0;
      while (sim.time() + 0.5 * sim.dt() < t_end) {
        sim.step();
        overlap = std::max(overlap, sim.last_totals().max_overlap);
      }
      const SeriesRow r = sim.diagnostics();
      const ParticleStore& p = sim.particles();
      for (std::size_t k = 0; k < p.n_owned(); ++k)
        if (norm(p.pos[k]) > 2.5) return std::string("escaped");
      if (overlap > 0.05) return "overlap " + fmt("%.3f", overlap);
      const double res = (balance(r) - b0) / r.drive_work;
      return std::abs(res) < 0.01 ? "" : "residual " + fmt("%.3g", res);
    };
  };
  out.push_back(
      {"range", true, false, [] { return drum(400, 0.01, 0.1, 1.8, 0.1); }, drum_check(0.5)});
  out.push_back({"20000", false, false, [] { return drum(20000, 0.01, 0.01, 10.0, 0.01); },
                 drum_check(0.02)});
  return out;
}

struct Result {
  std::string name, integrator;
  double auto_dt = 0.0, passing = 0.0, failing = 0.0;
  std::string reason;
};

Result margins(const Case& c, IntegratorKind integrator, const std::vector<double>& factors) {
  Result out;
  out.name = c.name;
  out.integrator = integrator == IntegratorKind::kVerlet ? "verlet" : "iterative";
  Scene s = c.scene();
  s.run.integrator = integrator;
  out.auto_dt = Simulation(s).dt();
  for (const double k : factors) {
    Scene at = s;
    at.run.dt_auto = false;
    at.run.dt = k * out.auto_dt;
    at.run.allow_unsafe_dt = true;
    std::string why;
    try {
      Simulation sim(at);
      why = c.run(sim);
    } catch (const UnstableError& e) {
      const std::string w = e.what();
      const std::size_t colon = w.find("): ");
      why = "exit 3: " + w.substr(colon == std::string::npos ? 0 : colon + 3, 60);
    }
    if (!why.empty()) {
      out.failing = k;
      out.reason = why;
      return out;
    }
    out.passing = k;
  }
  out.reason = "passes every factor tried";
  return out;
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
    } else {
      std::fprintf(stderr, "usage: dt_margins [--quick] [--no-plot] [--results DIR]\n");
      return 2;
    }
  }
  const std::vector<double> factors =
      quick ? std::vector<double>{1, 2, 4, 8} : std::vector<double>{1, 1.5, 2, 3, 4, 6, 8, 12, 16};
  std::filesystem::create_directories(results);
  std::vector<Result> rows;
  std::printf("%-8s %-10s %11s %9s %9s  %s\n", "case", "integrator", "auto_dt_s", "passes_x",
              "fails_x", "first failure");
  for (const Case& c : cases()) {
    if (quick && !c.quick) continue;
    for (const IntegratorKind integ : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
      if (integ == IntegratorKind::kIterative && !c.iterative_too) continue;
      const Result r = margins(c, integ, factors);
      std::printf("%-8s %-10s %11.4g %9.3g %9.3g  %s\n", r.name.c_str(), r.integrator.c_str(),
                  r.auto_dt, r.passing, r.failing, r.reason.c_str());
      std::fflush(stdout);
      rows.push_back(r);
    }
  }
  const std::string csv = results + "/dt_margins.csv";
  std::ofstream f(csv);
  f << "case,integrator,auto_dt,largest_passing_factor,first_failing_factor,reason\n";
  for (const Result& r : rows)
    f << r.name << "," << r.integrator << "," << r.auto_dt << "," << r.passing << "," << r.failing
      << ",\"" << r.reason << "\"\n";
  f.close();  // the plot script reads it
  std::printf("wrote %s\n", csv.c_str());
  if (plot) {
    const std::string png = results + "/dt_margins.png";
    const std::string cmd = "/usr/bin/python3 " DEM2D_SOURCE_DIR "/post/plot_dt_margins.py '" +
                            csv + "' -o '" + png + "'";
    if (std::system(cmd.c_str()) != 0) std::printf("dt_margins: the plot script failed\n");
  }
  return 0;
}
