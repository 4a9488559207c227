// Domain: the only way the physics talks to other processes (docs/architecture.md).
//
// The core calls these verbs at fixed points of a step; the serial implementation below is
// trivial and is what the core's tests use. src/parallel/ implements them with MPI (angular
// sectors, halo exchange, migration) without the physics ever seeing MPI.
//
// When the core calls them (Simulation::rebuild and refresh_ghosts in core/run/simulation.cpp, the
// end-of-step round in core/step/integrators.cpp):
//   construction: every rank holds the same full set of particles -> adopt() keeps this
//     rank's own, then the first rebuild;
//   a neighbour rebuild (decided with any(), so on every rank at the same step):
//     migrate() (particles that left this rank's region go to their new owner with every
//     registered field and the contact histories that involve them, as HistoryRecords sized
//     from the contact model's declared slots) -> exchange_halo() (a new
//     ghost set) -> the core builds the neighbour lists over owned + ghosts;
//   every other force evaluation: refresh_ghosts() (positions, velocities, spins of the same
//     ghosts, in the same slots);
//   the end of a velocity-Verlet step: exchange_step() in one round both decides the next step
//     (a maximum over ranks: stability, rebuild) and hands every ghost the state its owner
//     will drift it to (the core computes it ahead for halo_sources()), so the next step needs
//     no refresh. One synchronisation per step instead of two.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/contact/contact_history.hpp"
#include "core/shape/particles.hpp"

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
  // Element-wise maximum over ranks, in place (several decisions in one reduction).
  virtual void max(std::span<double> /*values*/) const {}
  // Element-wise sums over ranks, in place (diagnostics: histograms, moments). Counts are
  // exact; doubles may differ in the last bits between rank counts.
  virtual void sum(std::span<std::int64_t> /*values*/) const {}
  virtual void sum(std::span<double> /*values*/) const {}
  // Every rank's values, rank 0's first (population changes: the parents broken in a step).
  virtual std::vector<std::int64_t> allgather(std::span<const std::int64_t> mine) const {
    return {mine.begin(), mine.end()};
  }
  // Whether a point lies in this rank's region (where a fed particle is born).
  virtual bool owns(Vec2 /*x*/) const { return true; }
  // The number of particles over all ranks changed (breakage, feed, sieve): the next
  // migrate() checks its count against `total`.
  virtual void population_changed(std::int64_t /*total*/) {}

  // Every rank holds the same full set of owned particles (the fill is deterministic): keep
  // those in this rank's region, drop the rest. halo_width: how far from its region a rank
  // needs ghost copies (largest contact reach plus the Verlet skin).
  virtual void adopt(ParticleStore&, double /*halo_width*/) {}
  // Move owned particles that left this rank's region to their new owner with all their
  // registered fields. `histories` holds this rank's contact histories on entry; records
  // that involve a leaving particle travel with it. On return it holds, sorted and without
  // duplicates, every history this rank needs for the particles it now owns. Throws
  // std::runtime_error (on every rank alike) when a particle jumped farther than the halo.
  virtual void migrate(ParticleStore&, HistoryRecords& /*histories*/) {}
  // Rebuild the ghost copies of other ranks' particles within the halo width of this rank's
  // region (all registered fields). Ghosts follow the owned particles in the store.
  virtual void exchange_halo(ParticleStore&) {}
  // Refresh the given fields of the same ghosts from their owners.
  virtual void refresh_ghosts(ParticleStore&, std::span<FieldBase* const> /*fields*/) {}
  // Owned particles that other ranks hold as ghosts since the last exchange_halo(): local
  // indices, ascending, without repeats. Empty on one rank.
  virtual std::span<const std::int32_t> halo_sources() const { return {}; }
  // One round: `values` becomes its element-wise maximum over ranks (a NaN anywhere gives NaN,
  // so the result is the same on every rank), and each ghost's `recv_fields` receive its
  // owner's `send_fields` (same types, in the same order; only halo_sources() are read).
  virtual void exchange_step(ParticleStore& /*p*/, std::span<FieldBase* const> /*send_fields*/,
                             std::span<FieldBase* const> /*recv_fields*/,
                             std::span<double> /*values*/) {}
  // Called after each neighbour rebuild with the work of each owned particle (1 + its share
  // of the listed pairs: half of a pair between two owned particles, all of a pair with a
  // ghost, which both ranks compute), in store order; the rank's work is their sum. A parallel
  // domain weights the sectors with it and may repartition at its next migrate() when the
  // imbalance grew.
  virtual void report_work(std::span<const double> /*particle_work*/) {}
};

}  // namespace dem2d
