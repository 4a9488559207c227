// Time integrators: one type per scheme, each with a step() that names its stages.
//
//   VelocityVerlet       kick-drift -> walls -> rebuild or refresh -> contact forces ->
//                        closing kick -> commit -> end-of-step round; when nothing looks at the
//                        state between this step and the next, the closing kick also does the
//                        next step's kick-drift (one pass over the store instead of two)
//   IterativeIntegrator  the thesis's scheme (T3-T8, T26-T33): walls -> rebuild? -> passes of
//                        (predict -> refresh -> contact forces -> accelerations) until the
//                        accelerations settle -> final predict -> commit -> end-of-step round
//
// An integrator owns its own state (Verlet: the rebuild decision and the ghosts' state computed
// ahead; iterative: the state at the start of the step) and moves the particles; everything else
// it asks of the simulation through StepStages. The end-of-step round is the step's one
// collective decision: stable or not (and, for Verlet, whether the next step rebuilds),
// identical on every rank.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "core/base/scene.hpp"
#include "core/contact/contact_engine.hpp"
#include "core/fast/verlet_passes.hpp"
#include "core/geometry/walls.hpp"
#include "core/shape/particles.hpp"
#include "core/step/domain.hpp"

namespace dem2d {

// When the neighbour lists must be rebuilt: two particles approach by at most twice the largest
// displacement since the last build, and a wall by at most what Walls::moved_since bounds
// (physics and lists: core/contact/neighbors.hpp).
class RebuildMonitor {
 public:
  explicit RebuildMonitor(double skin = 0.0) : skin_(skin) {}
  // The state at a build: owned positions, the walls' pose, the time.
  void record(const ParticleStore& p, const Walls& walls, double time);
  const Vec2* positions_at_build() const { return pos_at_build_.data(); }
  // True when particles that moved at most `displacement` since the build, with the walls
  // `ahead` seconds past `time`, may have come within the skin of a pair not listed.
  bool due(double displacement, const Walls& walls, double time, double ahead) const;
  double skin() const { return skin_; }

 private:
  double skin_;
  Array<Vec2> pos_at_build_;
  WallPose walls_at_build_;
};

// The stages of a step that belong to the simulation as a whole (core/run/simulation.cpp); an
// integrator calls them in its order.
class StepStages {
 public:
  virtual ParticleStore& particles() = 0;
  virtual Domain& domain() = 0;
  virtual const Walls& walls() const = 0;
  virtual const RebuildMonitor& rebuilds() const = 0;
  virtual const EvaluationTotals& totals() const = 0;
  virtual double time() const = 0;
  // Advance the clock by one step and put the walls where they are then.
  virtual void advance_clock() = 0;
  // Migrate, new ghosts, new neighbour lists (called on every rank at the same step).
  virtual void rebuild() = 0;
  // Positions, velocities and spins of the ghosts from their owners.
  virtual void refresh_ghosts() = 0;
  // The fields refresh_ghosts moves (Verlet hands them ahead at the end of a step).
  virtual std::span<FieldBase* const> ghost_fields() = 0;
  // Contact forces and torques at the current state into the accumulators (cleared first, the
  // owned ones unless `owned_cleared`); histories advanced by dt into the trial slots.
  virtual void contact_forces(double dt, bool owned_cleared) = 0;
  // Lines for the drift about to run to write the owned particles' new state into, read by the
  // next contact_forces (core/fast/kinematics_mirror.hpp); nullptr when the contact loop keeps
  // none.
  virtual PairKinematics* drift_mirror() = 0;
  // After the step's force evaluation: whether the ore models change the population at this
  // step's end (they plan their population step now; collective; false without ore models). The
  // end state is then read: the step does not run ahead.
  virtual bool population_changes() = 0;
  // The trial histories become the committed ones; the step's energies are booked, with
  // `late_loss` (J) added to the dissipation the contact laws reported (Verlet's completion of
  // their work to the end-of-step velocity).
  virtual void commit(double dt, double late_loss) = 0;

 protected:
  ~StepStages() = default;
};

// The end-of-step round's verdict (the same on every rank) and this rank's checksum of the
// accelerations (and, Verlet, positions): non-finite when something blew up here.
// A particle may move at most this many of its radii in one step. Beyond it a contact could
// begin at an overlap past kMaxOverlapRatio, or two bodies pass through each other unseen; the
// safe dt keeps a particle's move per step some hundred times smaller.
inline constexpr double kMaxStepMotion = 0.25;

struct StepOutcome {
  bool unstable = false;
  double checksum = 0.0;
  // This rank's largest move per step in radii (Verlet: the coming drift, dt |v + a dt/2| / r;
  // iterative: the step just taken, |x1 - x0| / r) and the id of the particle making it.
  double motion = 0.0;
  std::int64_t motion_id = -1;
  // Iterative: the passes did not settle and the last two moved some particle's end position by
  // more than IterativeIntegrator::kMaxUnsettledShift of its radius, the same on every rank; the
  // largest such shifts of the last two passes (IterativeIntegrator::largest_change), this
  // rank's largest of the last one and its particle.
  bool diverged = false;
  double shift_first = 0.0, shift_last = 0.0;
  double shift_mine = 0.0;
  std::int64_t shift_id = -1;
};

// Passes of force evaluation per step (always 1 for Verlet).
struct PassCounter {
  int last = 0;
  std::int64_t total = 0;
  std::int64_t since_row = 0, steps_since_row = 0;
  std::int64_t unconverged_steps = 0;
  void add(int passes) {
    last = passes;
    total += passes;
    since_row += passes;
    steps_since_row += 1;
  }
  double mean_since_row() const {
    return steps_since_row > 0
               ? static_cast<double>(since_row) / static_cast<double>(steps_since_row)
               : static_cast<double>(last);
  }
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  // Advance the particles by one step of dt, ending with the step's round.
  virtual StepOutcome step(StepStages& s) = 0;
  // Whether the step about to run may leave the store one drift ahead (Verlet: the closing kick
  // fused with the next kick-drift): only when nothing reads or changes the particles before the
  // next step, and never by default.
  virtual void allow_run_ahead(bool /*allowed*/) {}
  // The last step left the store one drift ahead (positions, velocities and spins of the next
  // step's drift; forces cleared).
  virtual bool ran_ahead() const { return false; }
  // Take the drift back, to the last bits (x - dt v, ...): the state a failed step's report shows.
  virtual void step_back(ParticleStore& /*p*/) {}
  // The store was replaced (a backup restored): the next step starts from it as it is.
  virtual void state_replaced() {}
  // After every rebuild (the owned set and the ghosts changed), in parallel runs.
  virtual void after_rebuild(std::size_t /*n_owned*/) {}
  // After particles were born or removed between steps and the forces evaluated anew at the
  // step's end state.
  virtual void after_population_change() {}
  const PassCounter& passes() const { return passes_; }
  PassCounter& passes() { return passes_; }

 protected:
  PassCounter passes_;
};

std::unique_ptr<Integrator> make_integrator(const RunSpec& run, double dt, Vec2 gravity);

// a = F/m + g and alpha = M/I of the owned particles (accelerate, core/fast/verlet_passes.hpp).
// Returns a checksum (a plain sum: any NaN or infinity makes it non-finite).
double accelerations(ParticleStore& p, Vec2 gravity);

// Velocity Verlet (kick-drift-kick); the velocity-dependent forces see the half-step velocity.
class VelocityVerlet final : public Integrator {
 public:
  VelocityVerlet(double dt, Vec2 gravity) : dt_(dt), gravity_(gravity) {}
  StepOutcome step(StepStages& s) override;
  void after_rebuild(std::size_t n_owned) override;
  // The new evaluation filled the elastic forces; the ghosts hold the current state.
  void after_population_change() override {
    elastic_cleared_ = false;
    ghosts_ahead_ = false;
    ahead_ = false;
  }
  void allow_run_ahead(bool allowed) override { run_ahead_allowed_ = allowed; }
  bool ran_ahead() const override { return ahead_; }
  void step_back(ParticleStore& p) override;
  void state_replaced() override { after_population_change(); }

 private:
  // The three stages of step(): the opening half kick and drift; the neighbour lists or the
  // ghosts (true: rebuilt); after the forces, the closing half kick, commit and round.
  void open_step(StepStages& s);
  bool lists_or_ghosts(StepStages& s);
  StepOutcome close_step(StepStages& s, bool rebuilt);
  void prepare_ghosts_ahead(const ParticleStore& p, std::span<const std::int32_t> sources);
  // The round: `max_overlap` the step's (totals()), and the rebuild decided for the next step.
  StepOutcome end_of_step_round(StepStages& s, const ClosingKick& c, double max_overlap);

  double dt_;
  Vec2 gravity_;
  bool run_ahead_allowed_ = false;  // for the step about to run (allow_run_ahead)
  bool ahead_ = false;              // the store is one drift ahead: the next step skips its drift
  bool rebuild_next_ = true;        // decided by the previous step's round
  bool ghosts_ahead_ = false;       // the ghosts already hold this step's drifted state
  bool elastic_cleared_ = false;    // the owned elastic forces are zero (closing_kick)
  // In parallel: the state the halo sources will drift to in the next step (their entries
  // only), sent to the ghosts in the end-of-step round.
  std::vector<FieldBase*> next_registry_;
  Field<Vec2> next_pos_{"next_position", next_registry_};
  Field<Vec2> next_vel_{"next_velocity", next_registry_};
  Field<double> next_omega_{"next_spin", next_registry_};
  // The angle as well when the ghosts carry it (shaped particles: Simulation's ghost fields end
  // with the angle), made at the first round that needs it.
  std::unique_ptr<Field<double>> next_theta_;
};

// The thesis's iterative refinement: predict the state at t + dt with the jerk
// b = (a1 - a0)/dt, re-evaluate forces there, repeat until the accelerations stop changing.
// Converged, this is Newmark's linear-acceleration method:
//   x1 = x0 + v0 dt + (2 a0 + a1) dt^2 / 6,  v1 = v0 + (a0 + a1) dt / 2.
class IterativeIntegrator final : public Integrator {
 public:
  IterativeIntegrator(double dt, Vec2 gravity, double tolerance, int max_passes)
      : dt_(dt), gravity_(gravity), tolerance_(tolerance), max_passes_(max_passes) {}
  // Unsettled passes that moved a particle's end position by more than this fraction of its
  // radius (one of the last two passes) are an error.
  static constexpr double kMaxUnsettledShift = 0.01;
  StepOutcome step(StepStages& s) override;

 private:
  bool rebuild_due(StepStages& s) const;
  void save_start(const ParticleStore& p);
  void predict(ParticleStore& p) const;
  // This rank's largest relative change of the accelerations since the last pass, and (out) the
  // largest shift of an end position it makes, in radii, with its particle.
  double largest_change(const ParticleStore& p, double& shift, std::int64_t& shift_id);
  double loss_power(const ParticleStore& p) const;
  double late_loss(const ParticleStore& p, double booked_power) const;
  void largest_motion(const ParticleStore& p, StepOutcome& out) const;
  StepOutcome end_of_step_round(StepStages& s, double checksum, StepOutcome out) const;

  double dt_;
  Vec2 gravity_;
  double tolerance_;
  int max_passes_;
  // The state at the start of the step and the latest accelerations.
  Array<Vec2> x0_, v0_, a0_, a1_;
  Array<double> th0_, w0_, al0_, al1_;
  // The previous step's loss forces and torques (late_loss).
  Array<Vec2> g0_;
  Array<double> m0_;
};

}  // namespace dem2d
