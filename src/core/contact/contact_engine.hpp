// ContactEngine: every contact of the particle system, and the forces they give.
//
// It owns the neighbour lists (core/contact/neighbors.hpp) with the contact histories beside them,
// the contact model chosen once from the scene (law x rolling model x tracker,
// core/contact/contact_models.hpp) with its coefficient table, and the batches the kernel works in.
// For a given state it computes forces, torques, the energies the contacts store and dissipate,
// and the torque and power of the drive (evaluate); it does not move particles.
//
// Histories: each listed contact carries the slots its model declares (history_slots()); a
// force evaluation writes the advanced values into trial slots, commit() makes them the
// committed ones at the end of a step. records() and adopt() key them by particle ids so that
// they travel with their particles (migration) and survive list rebuilds.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "core/base/scene.hpp"
#include "core/contact/contact_history.hpp"
#include "core/contact/materials.hpp"
#include "core/contact/neighbors.hpp"
#include "core/fast/kinematics_mirror.hpp"
#include "core/geometry/wall_loads.hpp"
#include "core/geometry/walls.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

// A run is unstable when an overlap exceeds this fraction of the smaller radius.
inline constexpr double kMaxOverlapRatio = 0.25;

// What one force evaluation adds up on this rank.
struct EvaluationTotals {
  std::int64_t contacts = 0;
  double dissipated = 0.0;                  // J in this step
  double elastic = 0.0;                     // J stored in all contacts
  double drum_torque = 0.0;                 // N m applied by the drive
  double lifter_torque = 0.0;               // N m of it through the lifters
  double drive_power = 0.0;                 // W delivered by moving walls
  double max_overlap = 0.0;                 // largest delta / min(r_i, r_j)
  std::int64_t worst_a = -1, worst_b = -1;  // ids at max_overlap (b = -1: a wall)
};

// The force loop for one contact model, instantiated at setup (contact_engine.cpp).
class ContactKernel {
 public:
  virtual ~ContactKernel() = default;
  virtual std::span<const HistorySlot> history_slots() const = 0;
  // Forces and torques of the listed contacts added to p.force and p.torque; trial histories
  // written; totals of this rank but the drive's; one load per wall contact into `loads`, in
  // the wall list's order.
  virtual void evaluate(ParticleStore& p, const Walls& walls, PairList& pairs,
                        WallPairList& wall_pairs, double dt, EvaluationTotals& totals,
                        std::vector<WallLoad>& loads) = 0;
  // The last evaluation's histories were committed / the lists were rebuilt or replaced.
  virtual void committed() = 0;
  virtual void lists_changed() = 0;
  // Whether evaluate writes the pairs' new histories over the committed ones instead of into
  // the trial slots (then the commit has nothing to swap; the same values either way).
  virtual bool histories_in_place() const { return false; }
  // The pair gather's mirror lines of the owned particles, for the drift about to run to write
  // (core/fast/kinematics_mirror.hpp); nullptr when this kernel keeps no mirror.
  virtual PairKinematics* drift_mirror(const ParticleStore&) { return nullptr; }
  // With the breakage tracker: the pair-list entries of the last evaluation whose breakage test
  // is due (TrackBreakage::test_due of their new histories), in list order. Empty otherwise.
  virtual std::span<const std::int32_t> breakage_tests_due() const { return {}; }
};
// The kernel of the scene's law, rolling model (none when no pair has rolling friction), tracker
// and the stepper that matches the integrator.
std::unique_ptr<ContactKernel> make_contact_kernel(const ContactSpec& spec, const PairTable& table,
                                                   IntegratorKind integrator);

class ContactEngine {
 public:
  explicit ContactEngine(const Scene& scene);

  // The history slots every contact carries (law, then rolling model, then tracker).
  std::span<const HistorySlot> history_slots() const { return kernel_->history_slots(); }
  const PairTable& materials() const { return table_; }

  // Rebuild the lists for the particles' current positions (owned and ghosts) and the walls'
  // current pose, within `skin`; histories of contacts still listed are kept.
  void build(const ParticleStore& p, const Walls& walls, double skin);
  // Forces of every listed contact for the current state; histories advanced by dt into the
  // trial slots, or over the committed ones (histories_in_place) (dt = 0: at rest in time). The
  // force accumulators are added to, not cleared.
  void evaluate(ParticleStore& p, const Walls& walls, double dt);
  // See ContactKernel::histories_in_place.
  bool histories_in_place() const { return kernel_->histories_in_place(); }
  // See ContactKernel::drift_mirror.
  PairKinematics* drift_mirror(const ParticleStore& p) { return kernel_->drift_mirror(p); }
  // The pairs' histories as the last evaluation wrote them: the committed ones when written in
  // place, else the trial slots (until the commit).
  const double* evaluated_pair_histories() const {
    return histories_in_place() ? pairs_.history.data() : pairs_.trial.data();
  }
  // See ContactKernel::breakage_tests_due.
  std::span<const std::int32_t> breakage_tests_due() const { return kernel_->breakage_tests_due(); }
  const EvaluationTotals& totals() const { return totals_; }
  // The last evaluation's wall loads (core/geometry/wall_loads.hpp), this rank's, in the wall
  // list's order.
  std::span<const WallLoad> wall_loads() const { return wall_loads_; }
  // The trial histories become the committed ones.
  void commit();

  // Committed histories that are not all zero, keyed by particle ids, sorted.
  HistoryRecords records() const;
  // Lists reduced to these keyed histories: the next build() carries them by key.
  void adopt(const HistoryRecords& records);
  // The work of each owned particle for load balancing: 1 + its share of the listed pairs
  // (half of a pair between two owned particles, all of a pair with a ghost). Multiples of 1/2,
  // so sums of them are exact in any order.
  std::vector<double> particle_work(std::size_t n_owned) const;

  const PairList& pairs() const { return pairs_; }
  const WallPairList& wall_pairs() const { return wall_pairs_; }
  // The lists with their committed histories, for the models that write a tracker slot between
  // steps (breakage: the level tested, the birth exclusions; core/mill/grinding.cpp).
  PairList& mutable_pairs() { return pairs_; }
  WallPairList& mutable_wall_pairs() { return wall_pairs_; }
  // Where the slot named `name` sits in a contact's history (throws std::logic_error if the
  // model has none).
  std::size_t history_offset(std::string_view name) const;
  std::int64_t builds() const { return search_.builds(); }
  double far_fraction() const { return search_.far_fraction(); }

 private:
  PairTable table_;
  std::unique_ptr<ContactKernel> kernel_;
  NeighborSearch search_;
  PairList pairs_;
  WallPairList wall_pairs_;
  EvaluationTotals totals_;
  std::vector<WallLoad> wall_loads_;
};

}  // namespace dem2d
