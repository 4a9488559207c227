// dem2d --check: the derived quantities of a valid deck (time scales, the time step, steps,
// memory, and the mill's numbers when it has a drum), as the report's text.
#pragma once

#include <cstdint>
#include <string>

#include "core/run/simulation.hpp"

namespace dem2d {

// A short timed trial of `scene` from its start on this core (built without a decomposition, no
// output): what a wall-time estimate rests on.
struct Trial {
  double particle_steps_per_second = 0.0;
  double seconds = 0.0;  // wall time of the trial
  std::int64_t steps = 0;
  std::string stopped;  // why the trial ended early (a guard), else empty
};
Trial timed_trial(const Scene& scene, double budget_seconds = 0.5);

// The report of the whole scene `sim` (built without a decomposition): "dem2d --check DECK: the
// deck is valid" and one line per quantity; the wall time estimated from `trial`.
std::string check_report(const Simulation& sim, const Trial& trial);

}  // namespace dem2d
