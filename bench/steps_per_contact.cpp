// steps_per_contact: the restitution error against the number of steps per Hertz contact, for
// both integrators: the measurement behind dt = "auto"'s rule
// N(e) = max(20, 50 (-ln e / ln 2)^1.77) (src/core/step/time_scales.hpp, docs/models.md "Why
// N(e)").
//
// Two thesis-steel balls (r = 0.1 m, E = 2e11 Pa, nu = 0.25, hertz-mindlin, no friction effect:
// head-on) meet at 2 x 20 m/s. dt = t_c / N with t_c = 2.868 (m*^2 / (E*^2 R* v))^(1/5), the
// elastic Hertz contact time at the closing speed v = 40 m/s (the time the auto dt divides).
// For each restitution e asked and each N, the impact is run at 8 phases of the first touch
// within a step (the gap at the start is u v dt, u = 1/16, 3/16, ..., 15/16) and the worst
// |e obtained / e - 1| is reported. N runs over 14, 20, 40, 80, 160 and N(e) itself.
// Output: the table on stdout and bench/results/steps_per_contact.csv (table only).
//
//   steps_per_contact [--results DIR]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "core/step/time_scales.hpp"
#include "settled_drum.hpp"

namespace dem2d {
namespace {

constexpr double kRadius = 0.1, kSpeed = 20.0;

Scene impact(double e, IntegratorKind integrator, double dt, double gap) {
  Scene s;
  s.deck_path = "steps_per_contact";
  MaterialSpec m = bench::steel();  // thesis Table 1
  m.restitution = e;
  m.rolling_friction = 0.0;
  s.materials = {m};
  s.run.gravity = {0.0, 0.0};
  s.run.integrator = integrator;
  s.run.dt_auto = false;
  s.run.dt = dt;
  s.run.allow_unsafe_dt = true;
  for (const double side : {-1.0, 1.0}) {
    ParticleSpec p;
    p.material = "steel";
    p.radius = kRadius;
    p.position = {side * (kRadius + 0.5 * gap), 0.0};
    p.velocity = {-side * kSpeed, 0.0};
    s.particles.push_back(p);
  }
  return s;
}

// The restitution obtained (relative speeds after / before).
double rebound(const Scene& s) {
  Simulation sim(s);
  bool touched = false;
  while (sim.time() < 1e-2 && !(touched && sim.last_totals().contacts == 0)) {
    sim.step();
    touched = touched || sim.last_totals().contacts > 0;
  }
  return (sim.particles().vel[1].x - sim.particles().vel[0].x) / (2.0 * kSpeed);
}

double hertz_time() {
  const double m = 4.0 / 3.0 * std::numbers::pi * kRadius * kRadius * kRadius * 7800.0;
  const double m_eff = 0.5 * m, r_eff = 0.5 * kRadius;
  const double e_star = 2.0e11 / (2.0 * (1.0 - 0.25 * 0.25));
  return 2.868 * std::pow(m_eff * m_eff / (e_star * e_star * r_eff * 2.0 * kSpeed), 0.2);
}

}  // namespace
}  // namespace dem2d

int main(int argc, char** argv) {
  using namespace dem2d;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
  if (argc == 3 && std::string(argv[1]) == "--results") results = argv[2];
  std::filesystem::create_directories(results);
  const double t_c = hertz_time();
  std::printf(
      "head-on steel at 2 x %.0f m/s, Hertz contact time %.4g s; worst |e obtained / e - 1| "
      "over 8 touch phases\n",
      kSpeed, t_c);
  std::ofstream csv(results + "/steps_per_contact.csv");
  csv << "integrator,restitution,steps_per_contact,is_rule,worst_relative_error\n";
  for (const IntegratorKind integ : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
    const char* name = integ == IntegratorKind::kVerlet ? "verlet" : "iterative";
    std::printf("\n%-9s %6s %8s %8s %8s %8s %8s   %s\n", name, "e", "14", "20", "40", "80", "160",
                "N(e): error");
    for (const double e : {0.05, 0.1, 0.3, 0.5, 0.73, 0.9, 0.99}) {
      const double rule = steps_per_contact_for(e);
      std::printf("%-9s %6.2f", "", e);
      const auto worst_at = [&](double n) {
        const double dt = t_c / n;
        double worst = 0.0;
        for (int k = 0; k < 8; ++k) {
          const double gap = (2 * k + 1) / 16.0 * 2.0 * kSpeed * dt;
          worst = std::max(worst, std::abs(rebound(impact(e, integ, dt, gap)) / e - 1.0));
        }
        return worst;
      };
      for (const double n : {14.0, 20.0, 40.0, 80.0, 160.0}) {
        const double worst = worst_at(n);
        std::printf(" %7.2f%%", 100.0 * worst);
        csv << name << "," << e << "," << n << ",0," << worst << "\n";
      }
      const double worst = worst_at(rule);
      std::printf("   %4.0f: %6.2f %%\n", rule, 100.0 * worst);
      csv << name << "," << e << "," << rule << ",1," << worst << "\n";
      std::fflush(stdout);
    }
  }
  std::printf("\nwrote %s/steps_per_contact.csv\n", results.c_str());
  return 0;
}
