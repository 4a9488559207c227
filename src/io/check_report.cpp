#include "io/check_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/base/errors.hpp"
#include "core/mill/mill_analytics.hpp"
#include "core/step/time_scales.hpp"
#include "io/text.hpp"

namespace dem2d {

namespace {

// How much longer a whole run takes than its first steps foretell (the fill still falling, few
// contacts), at most: the shipped drum decks without snapshots took 0.94-1.33 times the estimate
// (docs/input.md, "What --check tells").
constexpr double kSettledCostFactor = 1.4;
// The same for superellipses, whose contacts cost 25-55 discs' (docs/performance.md,
// "Superellipses") while the trial's falling fill has few: inputs/shapes.in's charges of
// rounded squares and ellipses took 11 and 13 times their estimates in processor time.
constexpr double kShapedSettledCostFactor = 20.0;

// "; asked: fill[0].bed_filling = 0.3": the fills that gave `key` (fill_fraction,
// bed_filling) and their values, or "" when none did.
std::string asked(const Scene& s, const char* key, double FillSpec::*value) {
  std::string out;
  for (const FillSpec& f : s.fills) {
    if (!(f.*value > 0.0)) continue;
    out += (out.empty() ? "; asked: " : ", ") + std::string("fill[") + std::to_string(f.index) +
           "]." + key + fmt_double(" = %g", f.*value);
  }
  return out;
}

// The mill's numbers.
std::string mill_check_lines(const Scene& s, const MillNumbers& m) {
  std::string out = fmt_double("  fill fraction:         %.4f (particle cross-sections / drum area",
                               m.fill_fraction) +
                    asked(s, "fill_fraction", &FillSpec::fill_fraction) + ")\n" +
                    fmt_double("  bed filling J:         %.3f", m.bed_filling) +
                    fmt_double(" (the bed with its voids / drum area, packing %.2f", kBedPacking) +
                    asked(s, "bed_filling", &FillSpec::bed_filling) + ")\n";
  out += fmt_double("  critical speed:        %.4f rad/s", m.critical_speed) +
         fmt_double(" = sqrt(g/R) (%.2f rpm);", m.critical_speed * 30.0 / std::numbers::pi) +
         fmt_double(" with fill (thesis T37) %.4f rad/s\n", m.critical_speed_with_fill);
  out += fmt_double("  drum speed:            %.4f rad/s", s.drum.speed) +
         fmt_double(" = %.3f of critical", m.speed_fraction) +
         fmt_double(" (Froude number %.4f)\n", m.froude);
  out += fmt_double("  2D to 3D:              the slice is %.4g m thick", m.slice_thickness) +
         " (the charge's mass-weighted mean diameter, sum(m d) / sum(m)); a mill L m long "
         "draws about L / " +
         fmt_double("%.4g times its power\n", m.slice_thickness);
  return out;
}

// What sets the time step, and how much larger it would be without the smallest restitution.
std::string dt_driver_lines(const TimeScales& ts) {
  std::string out = "  dt set by:             the shortest contact, " + ts.hertz_pair;
  if (ts.steps_per_contact > steps_per_contact_for(1.0))
    out += fmt_double(", resolved with %.0f steps for", ts.steps_per_contact) +
           fmt_double(" the restitution %.3f of ", ts.restitution_min) + ts.restitution_pair +
           fmt_double(" (%.3g times as many as a restitution of 0.7 or more needs)",
                      ts.steps_per_contact / steps_per_contact_for(1.0));
  return out + "\n";
}

// The run's wall time on one rank from the trial's rate.
std::string wall_time_line(const Trial& trial, double particle_steps, bool births, bool shaped) {
  if (trial.particle_steps_per_second <= 0.0)
    return "  wall time estimate:    none (" +
           (trial.stopped.empty() ? std::string("the trial took no step") : trial.stopped) + ")\n";
  return fmt_double("  wall time estimate:    %.3g s on 1 rank",
                    particle_steps / trial.particle_steps_per_second) +
         fmt_double(" (%.3g particle-steps/s", trial.particle_steps_per_second) +
         fmt_double(" over the first %.0f steps", static_cast<double>(trial.steps)) +
         (shaped ? fmt_double("; up to %.0fx as long once the superellipses touch",
                              kShapedSettledCostFactor)
                 : fmt_double("; up to %.1fx as long once the charge has settled",
                              kSettledCostFactor)) +
         "; snapshots add their own cost" +
         (births ? "; particles born by breakage and feed are not counted" : "") + ")\n";
}

// When ore starts to break, and whether the fill is still falling then: the free fall of its
// highest particle to the lowest point of the shell.
std::string breakage_line(const Scene& s, const ParticleStore& p);

// The ore's laws and where it leaves, in words (docs/models.md, "Grinding").
std::string ore_lines(const Scene& s) {
  std::string out;
  if (s.breakage.present) {
    const BreakageSpec& b = s.breakage;
    out += b.model == BreakageModel::kVogelPeukert
               ? fmt::format(
                     "  breakage law:          Vogel-Peukert, f_mat {:g} kg/(J m), x W_min "
                     "{:g} J m/kg",
                     b.f_mat, b.xw_min)
               : fmt::format("  breakage law:          thesis, E_min {:g} J, S {:g} 1/J",
                             b.minimum_energy, b.strength);
    out += b.energy_split == EnergySplit::kCompliance ? ", each body its compliance share"
                                                      : ", each body the whole energy";
    out += b.fragments == FragmentLaw::kT10
               ? fmt::format("; t10 progeny (A {:g} %, b {:g} t/kWh), fines below {:g} m\n",
                             b.t10_a, b.t10_b, b.fines_diameter)
               : fmt::format("; {}-{} equal fragments\n", b.fragments_min, b.fragments_max);
  }
  if (s.sieve.present) {
    const SieveSpec& v = s.sieve;
    out +=
        fmt::format("  discharge:             ore narrower than {:g} m (a diameter) ", v.aperture);
    if (v.type == DischargeType::kGrate)
      out += fmt::format("in the grate ring, the last {:g} m inside the shell\n", v.grate_width);
    else if (v.type == DischargeType::kOverflow)
      out += fmt::format("above an ore hold-up of {:g} kg, the finest first\n", v.holdup);
    else
      out += fmt::format("in the box [{:g}, {:g}] to [{:g}, {:g}]\n", v.box_min.x, v.box_min.y,
                         v.box_max.x, v.box_max.y);
  }
  return out;
}

std::string breakage_line(const Scene& s, const ParticleStore& p) {
  std::string out =
      fmt_double("  breakage from:         t = %.4g s (breakage.start)", s.breakage.start);
  const double g = norm(s.run.gravity);
  if (!s.drum.present || g <= 0.0 || p.n_owned() == 0) return out + "\n";
  double top = -std::numeric_limits<double>::max();
  for (std::size_t k = 0; k < p.n_owned(); ++k) top = std::max(top, p.pos[k].y + p.radius[k]);
  const double fall = std::sqrt(2.0 * std::max(0.0, top - (s.drum.center.y - s.drum.radius)) / g);
  if (s.breakage.start < fall)
    out += fmt_double("; the fill falls until about %.2g s (its highest particle to the shell):",
                      fall) +
           " ore hit before the charge settles breaks in the fall; set breakage.start later to "
           "break ore in the tumbling charge only";
  return out + "\n";
}

}  // namespace

Trial timed_trial(const Scene& scene, double budget_seconds) {
  using Clock = std::chrono::steady_clock;
  Trial trial;
  Simulation sim(scene);
  const auto start = Clock::now();
  double particle_steps = 0.0;
  try {
    while (sim.time() + 0.5 * sim.dt() < scene.run.duration &&
           std::chrono::duration<double>(Clock::now() - start).count() < budget_seconds) {
      sim.step(true);
      particle_steps += static_cast<double>(sim.particles().n_owned());
      ++trial.steps;
    }
  } catch (const UnstableError& e) {
    trial.stopped = std::string("the trial stopped: ") + e.what();
  }
  trial.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (trial.steps > 0 && trial.seconds > 0.0)
    trial.particle_steps_per_second = particle_steps / trial.seconds;
  return trial;
}

std::string check_report(const Simulation& sim, const Trial& trial) {
  const Scene& s = sim.scene();
  const ParticleStore& p = sim.particles();
  const TimeScales& ts = sim.scales();
  std::string out = "dem2d --check " + s.deck_path + ": the deck is valid\n";
  if (!s.title.empty()) out += "  title:                 " + s.title + "\n";
  out += "  particles:             " + std::to_string(p.n_owned()) + "\n";
  if (s.drum.present) out += mill_check_lines(s, mill_numbers(s, charge_sizes(p, Domain{})));
  if (s.breakage.present) out += breakage_line(s, p);
  out += ore_lines(s);
  out += fmt_double("  Rayleigh time:         %.4e s (smallest particle)\n", ts.rayleigh);
  out += fmt_double("  Hertz contact time:    %.4e s", ts.hertz) +
         fmt_double(" at %.3f m/s (largest expected impact speed)\n", ts.impact_speed);
  out += fmt_double("  smallest restitution:  %.3f", ts.restitution_min) +
         fmt_double(" -> Hertz contact resolved with %.0f steps (1 %% restitution)\n",
                    ts.steps_per_contact);
  out += fmt_double("  safe dt:               %.4e s (dt = \"auto\")", ts.safe_dt) +
         fmt_double("; refused above %.4e s\n", ts.limit_dt);
  out += dt_driver_lines(ts);
  out += fmt_double("  chosen dt:             %.4e s", sim.dt()) +
         fmt_double(" (%.3f of the safe dt)\n", sim.dt() / ts.safe_dt);
  const double steps = std::ceil(s.run.duration / sim.dt() - 0.5);
  out += fmt_double("  steps:                 %.0f", steps) +
         fmt_double(" for %.4g s simulated\n", s.run.duration);
  out += wall_time_line(trial, steps * static_cast<double>(p.n_owned()),
                        s.breakage.present || s.feed.present, has_shaped_particles(s));
  const double bytes =
      static_cast<double>(p.n_owned()) * p.bytes_per_particle() +
      static_cast<double>(sim.pairs().size()) * (2 * 4 + 2 * 8 + 2 * 8 * sim.pairs().width);
  out += fmt_double("  memory estimate:       %.1f MiB\n", 2.0 * bytes / (1024.0 * 1024.0));
  out += fmt_double("  neighbour skin:        %.4g m\n", sim.skin());
  return out;
}

}  // namespace dem2d
