// Simulation: one run of the particle system through time.
//
// One step (architecture.md):
//   integrator predicts -> [parallel: migrate, halo] -> neighbour rebuild if anything moved
//   half the skin -> forces (contact law x pairs, walls, gravity) -> integrator corrects
//   (-> repeat for the iterative integrator) -> contact histories committed.
// The contact law and rolling model are chosen once in the constructor: the force kernel is a
// function pointer to the pair loop instantiated for that (law, rolling) combination.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/contact_batch.hpp"
#include "core/diagnostics.hpp"
#include "core/domain.hpp"
#include "core/materials.hpp"
#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "core/scene.hpp"
#include "core/walls.hpp"

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

// Derived time scales of a scene (interface.md --check).
struct TimeScales {
  double rayleigh = 0.0;       // s, smallest Rayleigh time pi r sqrt(rho/G)/(0.1631 nu + 0.8766)
  double hertz = 0.0;          // s, smallest Hertz contact time at the impact speed below
  double impact_speed = 0.0;   // m/s, largest expected impact speed
  double restitution_min = 1.0;  // smallest restitution of the material pairs present
  double steps_per_contact = 0.0;  // Hertz contact resolved with this many steps (see below)
  double safe_dt = 0.0;        // s, what dt = "auto" picks
  double limit_dt = 0.0;       // s, above this a dt is refused: 0.5 * min(rayleigh, hertz)
};

// Steps per Hertz contact that keep the restitution obtained within 1 % of the one asked
// (measured with both integrators, head-on steel at 40 m/s, worst of 8 contact phases: the
// error is first order, about C(e)/steps with C = 32 (-ln e / ln 2)^1.77 %, from where contact
// starts and ends inside a step). N = max(20, 50 (-ln e / ln 2)^1.77) aims at 0.65 %: 20 for
// e >= 0.7, 50 at e = 0.5, 420 at e = 0.1.
double steps_per_contact_for(double restitution);
TimeScales time_scales(const Scene& scene, const ParticleStore& particles);

// A run is unstable when an overlap exceeds this fraction of the smaller radius.
inline constexpr double kMaxOverlapRatio = 0.25;

struct EvaluationTotals {
  std::int64_t contacts = 0;
  double dissipated = 0.0;   // J in this step
  double elastic = 0.0;      // J stored in all contacts
  double drum_torque = 0.0;  // N m applied by the drive
  double drive_power = 0.0;  // W delivered by moving walls
  double max_overlap = 0.0;  // largest delta / min(r_i, r_j)
  std::int64_t worst_a = -1, worst_b = -1;  // ids at max_overlap (b = -1: a wall)
};

class Simulation;
using ForceKernel = void (*)(Simulation&, double dt, EvaluationTotals&);

class Simulation {
 public:
  // Builds walls and particles from the scene and evaluates the initial forces. Throws
  // InputError for an impossible placement or an unsafe dt.
  explicit Simulation(const Scene& scene, Domain* domain = nullptr);

  void step();
  void run_until(double t_end);

  SeriesRow diagnostics() const;
  // Start a new averaging window for the `passes` column (after a series row is written).
  void reset_pass_window();
  double time() const { return time_; }
  std::int64_t step_count() const { return step_; }
  double dt() const { return dt_; }
  double skin() const { return skin_; }
  double halo_width() const { return halo_width_; }
  const TimeScales& scales() const { return scales_; }
  const Scene& scene() const { return scene_; }
  ParticleStore& particles() { return particles_; }
  const ParticleStore& particles() const { return particles_; }
  const Walls& walls() const { return walls_; }
  const PairTable& pair_table() const { return pair_table_; }
  const PairList& pairs() const { return pairs_; }
  const WallPairList& wall_pairs() const { return wall_pairs_; }
  std::int64_t neighbor_builds() const { return search_.builds(); }
  std::int64_t passes_total() const { return passes_total_; }
  std::int64_t unconverged_steps() const { return unconverged_steps_; }
  int last_passes() const { return last_passes_; }
  const EvaluationTotals& last_totals() const { return totals_; }

  // Force a neighbour-list rebuild (after particles were moved or added by hand).
  void rebuild();
  // Recompute forces and accelerations at the current state without advancing (dt = 0: no
  // history change). Used after construction and by tests.
  void refresh_forces();

  // Internals used by the force kernels.
  Domain& domain() { return *domain_; }
  double rolling_damping() const { return scene_.contact.rolling_damping; }
  PairList& pair_list() { return pairs_; }
  ContactBatch& contact_batch() { return batch_; }
  WallBatch& wall_batch() { return wall_batch_; }
  WallPairList& wall_pair_list() { return wall_pairs_; }

 private:
  // Forces, torques and accelerations at the current state; contact histories advanced by
  // dt_history into the trial slots. kick != 0 also applies v += kick a (Verlet's closing half
  // kick); owned_cleared: the owned particles' accumulators are already zero.
  void evaluate_forces(double dt_history, double kick = 0.0, bool owned_cleared = false);
  void step_verlet();
  void step_iterative();
  bool rebuild_needed(double max_displacement) const;
  // Contact histories keyed by ids (parallel rebuilds: they travel with migrating particles).
  HistoryRecords history_records() const;
  void adopt_history_records(const HistoryRecords& records);
  void check_stability();
  void save_backup();
  void restore_backup();
  void commit_history();
  void account(const EvaluationTotals& t, double dt);

  Scene scene_;
  Domain serial_domain_;
  Domain* domain_;
  ParticleStore particles_;
  Walls walls_;
  PairTable pair_table_;
  NeighborSearch search_;
  PairList pairs_;
  WallPairList wall_pairs_;
  ForceKernel kernel_ = nullptr;
  ContactBatch batch_;
  WallBatch wall_batch_;
  TimeScales scales_;

  double dt_ = 0.0;
  double time_ = 0.0;
  std::int64_t step_ = 0;
  double skin_ = 0.0;
  double halo_width_ = 0.0;
  std::vector<FieldBase*> ghost_fields_;  // refreshed on ghosts every force evaluation
  // Velocity Verlet in parallel: the state the halo sources will drift to in the next step
  // (their next_* entries only), sent to the ghosts at the end of a step (exchange_step).
  std::vector<FieldBase*> next_registry_;
  Field<Vec2> next_pos_{"next_position", next_registry_};
  Field<Vec2> next_vel_{"next_velocity", next_registry_};
  Field<double> next_omega_{"next_spin", next_registry_};
  bool ghosts_ahead_ = false;  // the ghosts already hold the coming step's drifted state
  std::vector<double> particle_work_;  // parallel: reported at each rebuild (Domain::report_work)
  Vec2 gravity_{};

  // Rebuild bookkeeping: positions and wall pose at the last build.
  Array<Vec2> pos_at_build_;
  double drum_angle_at_build_ = 0.0;
  double time_at_build_ = 0.0;
  // Verlet: maxima over owned particles of |x - x_build|^2 and |v + a dt/2|^2 at the end of a
  // step, and the rebuild decision they give for the next step (check_stability).
  double next_disp2_ = 0.0, next_speed2_ = 0.0;
  bool rebuild_next_ = true;

  // Iterative integrator: state at the start of the step.
  Array<Vec2> x0_, v0_, a0_, a1_;
  Array<double> th0_, w0_, al0_, al1_;
  int last_passes_ = 0;
  std::int64_t passes_total_ = 0;
  std::int64_t passes_since_row_ = 0;
  std::int64_t steps_since_row_ = 0;
  std::int64_t unconverged_steps_ = 0;

  // Energy bookkeeping.
  EvaluationTotals totals_;
  double dissipated_ = 0.0;
  double drive_work_ = 0.0;
  double accel_checksum_ = 0.0;

  // Last known good state (for the snapshot written when a run blows up).
  std::vector<Vec2> backup_pos_, backup_vel_;
  std::vector<double> backup_theta_, backup_omega_;
  std::vector<std::int64_t> backup_id_;
  std::int64_t builds_at_backup_ = 0;
  double backup_time_ = 0.0;
  std::int64_t backup_step_ = 0;
};

}  // namespace dem2d
