#include "io/check_report.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/mill/mill_analytics.hpp"
#include "io/text.hpp"

namespace dem2d {

namespace {

// The mill's numbers.
std::string mill_check_lines(const Scene& s, const MillNumbers& m) {
  std::string out =
      fmt_double("  fill fraction:         %.4f (particle cross-sections / drum area)\n",
                 m.fill_fraction) +
      fmt_double("  bed filling J:         %.3f", m.bed_filling) +
      fmt_double(" (the bed with its voids / drum area, packing %.2f)\n", kBedPacking);
  out += fmt_double("  critical speed:        %.4f rad/s", m.critical_speed) +
         fmt_double(" = sqrt(g/R) (%.2f rpm);", m.critical_speed * 30.0 / std::numbers::pi) +
         fmt_double(" with fill (thesis T37) %.4f rad/s\n", m.critical_speed_with_fill);
  out += fmt_double("  drum speed:            %.4f rad/s", s.drum.speed) +
         fmt_double(" = %.3f of critical", m.speed_fraction) +
         fmt_double(" (Froude number %.4f)\n", m.froude);
  out += fmt_double("  2D to 3D:              the slice is %.4g m thick", m.slice_thickness) +
         " (the largest ball's diameter); a mill L m long draws about L / " +
         fmt_double("%.4g times its power\n", m.slice_thickness);
  return out;
}

}  // namespace

std::string check_report(const Simulation& sim) {
  const Scene& s = sim.scene();
  const ParticleStore& p = sim.particles();
  const TimeScales& ts = sim.scales();
  std::string out = "dem2d --check " + s.deck_path + ": the deck is valid\n";
  if (!s.title.empty()) out += "  title:                 " + s.title + "\n";
  out += "  particles:             " + std::to_string(p.n_owned()) + "\n";
  double area = 0.0, r_max = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    area += std::numbers::pi * p.radius[k] * p.radius[k];
    r_max = std::max(r_max, p.radius[k]);
  }
  if (s.drum.present) out += mill_check_lines(s, mill_numbers(s, area, r_max));
  out += fmt_double("  Rayleigh time:         %.4e s (smallest particle)\n", ts.rayleigh);
  out += fmt_double("  Hertz contact time:    %.4e s", ts.hertz) +
         fmt_double(" at %.3f m/s (largest expected impact speed)\n", ts.impact_speed);
  out += fmt_double("  smallest restitution:  %.3f", ts.restitution_min) +
         fmt_double(" -> Hertz contact resolved with %.0f steps (1 %% restitution)\n",
                    ts.steps_per_contact);
  out += fmt_double("  safe dt:               %.4e s (dt = \"auto\")", ts.safe_dt) +
         fmt_double("; refused above %.4e s\n", ts.limit_dt);
  out += fmt_double("  chosen dt:             %.4e s", sim.dt()) +
         fmt_double(" (%.3f of the safe dt)\n", sim.dt() / ts.safe_dt);
  const double steps = std::ceil(s.run.duration / sim.dt() - 0.5);
  out += fmt_double("  steps:                 %.0f", steps) +
         fmt_double(" for %.4g s simulated\n", s.run.duration);
  const double bytes =
      static_cast<double>(p.n_owned()) * p.bytes_per_particle() +
      static_cast<double>(sim.pairs().size()) * (2 * 4 + 2 * 8 + 2 * 8 * sim.pairs().width);
  out += fmt_double("  memory estimate:       %.1f MiB\n", 2.0 * bytes / (1024.0 * 1024.0));
  out += fmt_double("  neighbour skin:        %.4g m\n", sim.skin());
  return out;
}

}  // namespace dem2d
