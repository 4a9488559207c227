// What run.json records of a finished run (io/run_json.hpp): timing, the neighbour builds, the
// iterative integrator's passes, the guards, the decomposition's per-rank figures and, for a
// mill, its numbers and the last analysis window's averages and regime.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "io/run_json.hpp"
#include "io/run_outputs.hpp"
#include "parallel/mpi_domain.hpp"

namespace dem2d {

struct RunFacts {
  std::int64_t particles_at_start = 0;  // over every rank, when this run started
  std::int64_t particles = 0;           // over every rank, at the end
  std::int64_t particle_steps = 0;      // each step's particle count, summed over this run
  double wall = 0.0;                    // s of wall time of the run loop
  std::int64_t steps_here = 0;  // the steps this process took (a restart continues the count)
  bool interrupted = false;     // stopped by SIGINT or SIGTERM
  std::string restarted_from;   // the checkpoint continued (--restart), empty for a new run
  std::vector<std::string> overrides;     // the --set options, in order
  std::vector<std::string> warnings;      // what the run warned of while it ran
  const LifterOutput* lifters = nullptr;  // the shell's model and last response (rank 0)
};

// Collective (the decomposition's per-rank figures and the mill's totals are gathered).
RunInfo run_info(const Simulation& sim, const MpiDomain& domain, const Scene& scene,
                 const RunFacts& facts);

}  // namespace dem2d
