// Simulation: one run of the particle system through time, wired from parts that each own
// their state (docs/architecture.md):
//   ParticleStore   the particles (core/shape/particles.hpp)
//   Walls           drum, lifters, segments at the current time (core/geometry/walls.hpp)
//   ContactEngine   neighbour lists, contact histories, the contact model and its kernel
//   Integrator      velocity Verlet or the thesis's iterative scheme (core/step/integrators.hpp)
//   RebuildMonitor  when the neighbour lists must be rebuilt
//   Domain          the other ranks (serial: trivial; src/parallel: MPI)
// One step is the integrator's step() (its stages name the algorithm), then the stability
// verdict of its end-of-step round. Simulation implements the stages that belong to the whole
// system (clock and walls, rebuild with migration and halo, ghost refresh, contact forces,
// commit with the energy ledger) and the diagnostics.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/base/scene.hpp"
#include "core/contact/contact_engine.hpp"
#include "core/contact/materials.hpp"
#include "core/contact/neighbors.hpp"
#include "core/fast/spatial_order.hpp"
#include "core/geometry/walls.hpp"
#include "core/mill/grinding.hpp"
#include "core/mill/mill_analytics.hpp"
#include "core/run/run_state.hpp"
#include "core/run/state_backup.hpp"
#include "core/shape/particles.hpp"
#include "core/step/diagnostics.hpp"
#include "core/step/domain.hpp"
#include "core/step/energy_ledger.hpp"
#include "core/step/integrators.hpp"
#include "core/step/time_scales.hpp"

namespace dem2d {

// The run became unstable (exit 3): the message names the step, time, particles and safe dt.
class UnstableError : public std::runtime_error {
 public:
  UnstableError(const std::string& what, std::int64_t step, double time)
      : std::runtime_error(what), step_(step), time_(time) {}
  std::int64_t step() const { return step_; }
  double time() const { return time_; }

 private:
  std::int64_t step_;
  double time_;
};

// Energy created beyond this fraction of the energy that went through the system (kinetic,
// rotational and elastic energy at the first step, plus drive work, dissipation, the change of
// potential energy, and sum m |g| r) makes a run unstable (exit 3). The balance error at the safe
// dt is about 1 % of an impact's energy (first order in dt) and 0.2 % in the waterfall; a Verlet
// impact at 6 x the safe dt already creates 9 %, at 8 x 36 % (restitution 0.96 for 0.73 asked).
inline constexpr double kEnergyCreatedTolerance = 0.05;
// The balance is checked every this many steps and at the deck's last step.
inline constexpr std::int64_t kEnergyCheckSteps = 1000;

// The run's guards. A non-finite state and the motion guard always stop the run: past them
// neither the contact search nor the decomposition's halo hold. The others may warn instead
// (run.guards = "warn").
enum class Guard { kFinite, kMotion, kOverlap, kEnergy, kPasses };
constexpr const char* guard_name(Guard g) {
  constexpr const char* kNames[] = {"finite", "motion", "overlap", "energy", "passes"};
  return kNames[static_cast<int>(g)];
}
constexpr bool guard_may_warn(Guard g) { return g != Guard::kFinite && g != Guard::kMotion; }

// A run resumed from a checkpoint (io/checkpoint.hpp reads it): the run's state (its rank_*
// shares already this rank's), every particle of the run with all its registered fields, and
// the contact histories.
struct Resumption {
  RunState state;
  std::size_t n_particles = 0;
  // One column per field of the particle store's registry, in registry order: n_particles
  // items of bytes_per_item() bytes each (the particles in any order, the same in every column).
  std::vector<std::vector<std::byte>> columns;
  HistoryRecords histories;  // every rank's, in any order, duplicates allowed
};

class Simulation final : private StepStages {
 public:
  // Builds walls and particles from the scene and evaluates the initial forces. Throws
  // InputError for an impossible placement or an unsafe dt.
  // With `resume`, the particles, histories and state are the checkpoint's instead, and the
  // run continues exactly where it stopped: the next step() is the one the interrupted run
  // would have taken (core/run/run_state.hpp says what is rebuilt rather than restored).
  explicit Simulation(const Scene& scene, Domain* domain = nullptr,
                      const Resumption* resume = nullptr);

  // One step. With `end_observed` false the caller promises to read and change nothing (no
  // particle, no output) before the next step(), so a Verlet step may leave the store one drift
  // ahead (the closing kick fused with the next kick-drift, the same bits; integrators.hpp).
  // The simulation itself keeps the state whole at the steps it checks or backs up.
  void step(bool end_observed = true);
  // Steps until t_end; the state is whole when it returns.
  void run_until(double t_end);
  // Whether steps may run ahead at all (default on): off, every step ends whole (tests compare).
  void set_run_ahead(bool on) { run_ahead_ = on; }
  // Steps so far that ended one drift ahead.
  std::int64_t steps_run_ahead() const { return steps_run_ahead_; }

  SeriesRow diagnostics() const;
  // The row of series.csv: diagnostics() and, with a drum, the charge's shape (collective); the
  // sample joins the analysis window, whose average power and regime the row carries.
  SeriesRow record_row();
  // The analysis window's averages and regime (drum scenes; kUnknown until it is full).
  WindowSummary mill_summary() const { return mill_window_.summary(); }
  // Collision spectra (output.collision_spectra): this rank's histograms; nullptr when off.
  const CollisionSpectra* spectra() const { return spectra_.get(); }
  // Start a new averaging window for the `passes` column (after a series row is written).
  void reset_pass_window();
  double time() const override { return time_; }
  std::int64_t step_count() const { return step_; }
  double dt() const { return dt_; }
  double skin() const { return rebuilds_.skin(); }
  double halo_width() const { return halo_width_; }
  const TimeScales& scales() const { return scales_; }
  const Scene& scene() const { return scene_; }
  ParticleStore& particles() override { return particles_; }
  const ParticleStore& particles() const { return particles_; }
  const Walls& walls() const override { return walls_; }
  const ContactEngine& contacts() const { return contacts_; }
  const PairTable& pair_table() const { return contacts_.materials(); }
  const PairList& pairs() const { return contacts_.pairs(); }
  const WallPairList& wall_pairs() const { return contacts_.wall_pairs(); }
  std::int64_t neighbor_builds() const { return builds_before_ + contacts_.builds(); }
  // Times this rank put its particles in spatial order (core/fast/spatial_order.hpp).
  std::int64_t spatial_sorts() const { return sort_policy_.sorts(); }
  std::int64_t passes_total() const { return integrator_->passes().total; }
  std::int64_t unconverged_steps() const { return integrator_->passes().unconverged_steps; }
  int last_passes() const { return integrator_->passes().last; }
  const EvaluationTotals& last_totals() const { return contacts_.totals(); }
  // The guards that fired (run.guards = "warn"), in the order they first fired; the same on
  // every rank.
  const std::vector<GuardRecord>& guard_records() const { return guards_; }
  // Ore scenes ([breakage], [feed] or [sieve]): breakage, feed and sieve; nullptr otherwise.
  Grinding* grinding() { return grinding_.get(); }
  const Grinding* grinding() const { return grinding_.get(); }

  // What a checkpoint holds besides the particles: this rank's state and committed histories.
  RunState run_state() const;
  HistoryRecords histories() const { return contacts_.records(); }

  // Force a neighbour-list rebuild (after particles were moved or added by hand).
  void rebuild() override;
  // Recompute forces and accelerations at the current state without advancing (dt = 0: no
  // history change). Used after construction and by tests.
  void refresh_forces();

 private:
  // StepStages (core/step/integrators.hpp).
  Domain& domain() override { return *domain_; }
  const RebuildMonitor& rebuilds() const override { return rebuilds_; }
  const EvaluationTotals& totals() const override { return contacts_.totals(); }
  void advance_clock() override;
  void refresh_ghosts() override;
  std::span<FieldBase* const> ghost_fields() override { return ghost_fields_; }
  void contact_forces(double dt, bool owned_cleared) override;
  PairKinematics* drift_mirror() override { return contacts_.drift_mirror(particles_); }
  bool population_changes() override;
  void commit(double dt, double late_loss) override;
  // Whether step k may leave the store one drift ahead: its end is not observed, nor the run's
  // last, nor checked or backed up.
  bool may_run_ahead(std::int64_t k, bool end_observed) const;
  // After a step: its count, the guard verdict, the energy check and the backup (step()).
  void after_step(const StepOutcome& outcome, bool ran_ahead);

  void choose_dt();
  void set_up_lists();
  // A particle outside the drum: UnstableError naming it (collective, at rebuilds).
  void check_contained();
  // Put the owned particles in spatial order if the policy says so; true if it did.
  bool sort_particles();
  bool build_lists(bool migrate);
  // The resuming constructor's part: particles, histories and state from the checkpoint.
  void load_particles(const Resumption& resume);
  void resume_from(const Resumption& resume);
  // After a committed step of an ore scene: breakage, sieve and feed; when the population
  // changed, the lists are rebuilt, births excluded, forces evaluated at the new state and the
  // energy the change released booked as dissipated (collective).
  void population_step();
  void grinding_row(SeriesRow& row) const;
  void set_up_analytics(const Resumption* resume);
  // This rank's kinetic, rotational, potential and elastic energy.
  double local_energy() const;
  // A guard fired (collective: every rank builds the same message). Throws UnstableError,
  // unless run.guards = "warn" and the state is finite: then it is recorded and the run goes on.
  void report_unstable(const StepOutcome& outcome);
  std::string unstable_reason(const StepOutcome& outcome, bool finite, Guard& guard);
  void guard_fired(Guard guard, const std::string& message);
  // The energy guard: energy created beyond kEnergyCreatedTolerance (collective).
  void check_energy();
  void take_energy_baseline();

  Scene scene_;
  Domain serial_domain_;
  Domain* domain_;
  ParticleStore particles_;
  Walls walls_;
  ContactEngine contacts_;
  SortPolicy sort_policy_;
  TimeScales scales_;
  double dt_ = 0.0;
  double halo_width_ = 0.0;
  std::unique_ptr<Integrator> integrator_;
  RebuildMonitor rebuilds_;
  std::vector<FieldBase*> ghost_fields_;  // refreshed on ghosts every force evaluation

  double time_ = 0.0;
  std::int64_t step_ = 0;
  EnergyLedger ledger_;  // this rank's share, since the start
  MillWindow mill_window_;
  std::unique_ptr<CollisionSpectra> spectra_;
  // The energy balance at the start, and the energy then in motion and in the springs.
  double balance0_ = 0.0, motion0_ = 0.0, potential0_ = 0.0, energy_floor_ = 0.0;
  bool baseline_taken_ = false;
  std::int64_t builds_before_ = 0;  // neighbour builds before a restart
  bool run_ahead_ = true;
  std::int64_t steps_run_ahead_ = 0;
  bool population_planned_ = false;  // this step's population step planned by the integrator
  // Last known good state, saved every kBackupSteps steps and after every rebuild.
  static constexpr std::int64_t kBackupSteps = 1000;
  StateBackup backup_;
  std::int64_t builds_at_backup_ = 0;
  std::vector<GuardRecord> guards_;
  std::unique_ptr<Grinding> grinding_;
};

}  // namespace dem2d
