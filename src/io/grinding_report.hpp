// What a comminution engineer reads of an ore scene (docs/output.md, "sizes.csv" and run.json's
// "grinding"): the size distributions of the feed, the product and the ore in the mill, F80,
// P80, the reduction ratio, and the drive's specific energy per tonne of product and per tonne
// of ore ground below the aperture.
#pragma once

#include <string>

#include "core/mill/grinding.hpp"
#include "core/run/simulation.hpp"
#include "io/run_json.hpp"

namespace dem2d {

// The sentence that goes with every kWh/t figure.
inline constexpr const char* kSliceCaveat =
    "a one-particle-thick slice: the drive's work and the masses are those of the slice's "
    "spheres; trends and ratios carry over to a mill, absolute kWh/t need the slice-to-mill "
    "scale-up (docs/models.md, \"Grinding\")";

struct GrindingReport {
  GrindingSizes sizes;        // the product summed over ranks
  SizeMasses mill;            // the ore in the mill now
  double drum_work = 0.0;     // J since the start
  double product_mass = 0.0;  // kg: discharged particles and fines
  double fines_mass = 0.0;    // kg
  double aperture = 0.0;      // m, 0 without a [sieve]
  double time = 0.0;
};

// Collective.
GrindingReport grinding_report(const Simulation& sim, const Domain& domain);

// run.json's "grinding" object.
JsonObject grinding_json(const GrindingReport& r);
// sizes.csv: one row per size class edge from the finest to the coarsest class that holds ore.
std::string sizes_csv_text(const GrindingReport& r);
// Writes DIR/sizes.csv (a temporary file renamed into place); throws IoError when it cannot.
void write_sizes_csv(const std::string& directory, const GrindingReport& r);

}  // namespace dem2d
