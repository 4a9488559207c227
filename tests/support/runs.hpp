// Runs of a Simulation the tests repeat, and what they measure on the way: an impact stepped
// until it has ended, a drum run to a time, the fastest particle.
#pragma once

#include <algorithm>
#include <cstddef>

#include "core/run/simulation.hpp"
#include "core/step/diagnostics.hpp"

namespace dem2d::testing_support {

// The largest speed of an owned particle.
inline double max_speed(const ParticleStore& p) {
  double v = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) v = std::max(v, norm(p.vel[k]));
  return v;
}

// Steps until a contact has begun and every contact has ended, or until time t_max: whether a
// contact began, and the largest overlap of any step (of the smaller radius).
struct ImpactRun {
  bool touched = false;
  double max_overlap = 0.0;
};
inline ImpactRun run_through_impact(Simulation& sim, double t_max) {
  ImpactRun out;
  while (sim.time() < t_max && !(out.touched && sim.last_totals().contacts == 0)) {
    sim.step();
    out.touched = out.touched || sim.last_totals().contacts > 0;
    out.max_overlap = std::max(out.max_overlap, sim.last_totals().max_overlap);
  }
  return out;
}

// A drum scene run to t_end: the largest overlap of any step (of the smaller radius) and the
// energy balance's residual over the drive work.
struct DrumRun {
  double max_overlap = 0.0, residual = 0.0;
};
inline DrumRun run_drum(Simulation& sim, double t_end) {
  const double b0 = energy_balance(sim.diagnostics());
  DrumRun out;
  while (sim.time() + 0.5 * sim.dt() < t_end) {
    sim.step();
    out.max_overlap = std::max(out.max_overlap, sim.last_totals().max_overlap);
  }
  const SeriesRow r = sim.diagnostics();
  out.residual = (energy_balance(r) - b0) / r.drive_work;
  return out;
}

}  // namespace dem2d::testing_support
