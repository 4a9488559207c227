// RunState: what, besides the particles and the contact histories, a run needs to continue
// exactly from the end of a step (checkpoints: io/checkpoint.hpp; restart: Simulation's
// resuming constructor).
//
// What is not here is rebuilt, and the answer is still the same bit for bit:
//   - the neighbour lists and the ghosts: the first step of a resumed run rebuilds them from
//     the particles, with the histories keyed by particle ids (a rebuild at another step
//     changes no particle's state: the pair and force-sum orders are canonical);
//   - the walls: their pose is a function of time (ramp_angle, ramp_speed);
//   - the random draws: counter-based, keyed by particle ids, partners and steps;
//   - the integrators' working state: velocity Verlet keeps only the accelerations (a
//     particle field), the iterative scheme the last loss forces (the force and elastic_force
//     fields).
// `rank_*` values are this rank's share of a sum over ranks; a run resumed on the same number
// of ranks takes them back rank by rank, on another number rank 0 takes their sum.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/mill/grinding.hpp"
#include "core/mill/mill_analytics.hpp"
#include "core/step/energy_ledger.hpp"
#include "core/step/integrators.hpp"

namespace dem2d {

// A guard that fired in a run with run.guards = "warn" (the run went on).
struct GuardRecord {
  std::string kind;        // guard_name: "overlap", "energy" or "passes"
  std::int64_t count = 0;  // steps (energy: checks, every kEnergyCheckSteps) at which it fired
  std::string first;       // the message of the first time, as the stopping error would say it
};

struct RunState {
  double time = 0.0;
  std::int64_t step = 0;
  // The time step and neighbour-list geometry chosen at the start (dt = "auto" and the skin
  // depend on the particles then, not on the particles now).
  double dt = 0.0, skin = 0.0, halo_width = 0.0;
  // The energy ledger, this rank's share; the balance at the start (global).
  EnergyLedger rank_ledger;
  bool baseline_taken = false;  // the balance at the start is taken as the first step starts
  double balance0 = 0.0, motion0 = 0.0, potential0 = 0.0, energy_floor = 0.0;
  PassCounter passes;
  std::int64_t neighbor_builds = 0;
  std::vector<GuardRecord> guards;
  GrindingState grinding;  // ore scenes only
  // Mill analytics: the analysis window's samples (global), and the collision spectra summed
  // over ranks (a resumed run gives them to rank 0).
  std::vector<MillSample> mill_samples;
  std::vector<std::int64_t> spectra_counts;
  std::vector<double> spectra_energies;
};

}  // namespace dem2d
