// dem2d --check: the derived quantities of a valid deck (time scales, the time step, steps,
// memory, and the mill's numbers when it has a drum), as the report's text.
#pragma once

#include <string>

#include "core/run/simulation.hpp"

namespace dem2d {

// The report of the whole scene `sim` (built without a decomposition): "dem2d --check DECK: the
// deck is valid" and one line per quantity.
std::string check_report(const Simulation& sim);

}  // namespace dem2d
