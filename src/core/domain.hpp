// Domain: the only way the physics talks to other processes (architecture.md).
//
// The core calls these verbs at fixed points of a step; the serial implementation below is
// trivial and is what the core's tests use. src/parallel/ implements them with MPI (angular
// sectors, halo exchange, migration) without the physics ever seeing MPI.
#pragma once

#include <cstdint>

#include "core/particles.hpp"

namespace dem2d {

class Domain {
 public:
  virtual ~Domain() = default;
  virtual int rank() const { return 0; }
  virtual int size() const { return 1; }
  // Reductions over ranks. Results are identical on every rank and independent of the rank
  // count where they feed back into the physics (max and logical or are exact).
  virtual double sum(double x) const { return x; }
  virtual double max(double x) const { return x; }
  virtual std::int64_t sum(std::int64_t x) const { return x; }
  virtual bool any(bool x) const { return x; }
  // Move owned particles that left this rank's region to their new owner (with all fields).
  virtual void migrate(ParticleStore&) {}
  // Rebuild ghost copies of other ranks' particles near this rank's region.
  virtual void exchange_halo(ParticleStore&, double /*halo_width*/) {}
  // Refresh ghost positions and velocities from their owners (same ghost set).
  virtual void refresh_ghosts(ParticleStore&) {}
};

}  // namespace dem2d
