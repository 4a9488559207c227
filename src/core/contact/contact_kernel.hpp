// The force kernel of one contact model (ContactModel<Law, Rolling, Tracker, Stepper>): the class
// and the helpers its phases share. Its members are defined by job in kernel_pairs.hpp (particle
// pairs: gather, evaluate, scatter), kernel_walls.hpp (particle-wall contacts and their load
// records) and kernel_release.hpp (the energy ended contacts release); kernel_factory.hpp makes
// one law's kernels and is included only by the kernels_*.cpp files, one per contact law, so that
// the laws' kernels compile in parallel (36 instantiations in one file took over 6 minutes under
// the sanitizers); contact_engine.cpp picks the law.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <tuple>
#include <type_traits>
#include <vector>

#include "core/contact/contact_batch.hpp"
#include "core/contact/contact_engine.hpp"
#include "core/contact/contact_models.hpp"
#include "core/fast/pair_gather.hpp"
#include "core/shape/disc.hpp"
#include "core/shape/superellipse.hpp"

namespace dem2d::kernels {

[[gnu::always_inline]] inline Pack load(const Array<double>& a, std::size_t c) {
  return Pack(a.data() + c, stdx::element_aligned);
}
[[gnu::always_inline]] inline void store(const Pack& v, Array<double>& a, std::size_t c) {
  v.copy_to(a.data() + c, stdx::element_aligned);
}

// Normal and tangential components of the relative velocity at the contact point (t = perp(n)).
template <class T>
[[gnu::always_inline]] inline void project_velocity(KinematicsT<T>& kin, T vrx, T vry, T nx, T ny) {
  const T tx = -ny, ty = nx;
  kin.v_n = vrx * nx + vry * ny;
  kin.v_t = vrx * tx + vry * ty;
}

// A contact's history between the batch columns (slot by slot, law first) and the model's
// History<Pack>.
template <class Model>
[[gnu::always_inline]] inline typename Model::template History<Pack> load_history(
    const HistoryColumns& h, std::size_t c) {
  typename Model::template History<Pack> out;
  std::size_t s = 0;
  for (Pack& v : out.law) v = load(h.old[s++], c);
  for (Pack& v : out.rolling) v = load(h.old[s++], c);
  for (Pack& v : out.tracker) v = load(h.old[s++], c);
  for (Pack& v : out.stepper) v = load(h.old[s++], c);
  return out;
}
template <class Model>
[[gnu::always_inline]] inline void store_history(const typename Model::template History<Pack>& in,
                                                 HistoryColumns& h, std::size_t c) {
  std::size_t s = 0;
  for (const Pack& v : in.law) store(v, h.fresh[s++], c);
  for (const Pack& v : in.rolling) store(v, h.fresh[s++], c);
  for (const Pack& v : in.tracker) store(v, h.fresh[s++], c);
  for (const Pack& v : in.stepper) store(v, h.fresh[s++], c);
}

inline std::size_t padded(std::size_t n) { return (n + kPackSize - 1) / kPackSize * kPackSize; }

// From this many particles (owned and ghosts) the canonical scatter fetches its partners' lines
// ahead (Kernel::scatter_pairs).
inline constexpr std::size_t kScatterPrefetchFrom = 50000;

// The force loop for one contact model and particle shape (docs/architecture.md, "Code
// conventions": written once, the model chosen at setup). Particle-particle contacts in canonical
// (lower id first, sorted) order, in chunks, then particle-wall contacts; each in the three phases
// of contact_batch.hpp. Both paths call Model::evaluate for the physics; they differ only in the
// geometry they gather and in what they scatter.
//
// Shape: the particle shape's narrow phase and inertia (core/shape/disc.hpp). The disc's arms lie
// along the normal, and its kernels take the disc's forms of arm x force and v + w x arm on
// scalars of the normal frame (and its pairs' gather, which may be vector); a shape whose arms
// leave the normal gets the vector forms, the scalar gather with each body's spin and angle,
// its own history slots after the model's, and lanes out of contact (its bounding circles
// overlap, its bodies do not) masked out.
template <class Model, class Shape = Disc>
class Kernel final : public ContactKernel {
  using Coeffs = typename Model::template Coeffs<double>;
  static constexpr std::size_t kModelWidth = Model::kHistoryWidth;
  static constexpr std::size_t kShapeWidth = Shape::kHistory.size();
  static constexpr std::size_t W = kModelWidth + kShapeWidth;
  static_assert(W <= kMaxHistorySlots, "raise kMaxHistorySlots");
  static_assert(!Shape::kArmsAlongNormal || kShapeWidth == 0,
                "a shape with history of its own takes the general path (kArmsAlongNormal false)");
  static constexpr bool kArmsApart = !Shape::kArmsAlongNormal;
  // The shape reads each body's semi-axes and exponent (the store's shape fields).
  static constexpr bool kSemiAxes = kShapeHasSemiAxes<Shape>;
  static_assert(!kSemiAxes || kArmsApart, "a shape with semi-axes takes the general path");

 public:
  Kernel(const ContactSpec& spec, const PairTable& table)
      : n_mat_(table.n_materials()),
        slots_(all_slots()),
        vector_gather_(kHaveVectorGather && !spec.scalar_gather && !kArmsApart) {
    for (int a = 0; a < n_mat_; ++a)
      for (int b = 0; b < n_mat_; ++b) coeffs_.push_back(Model::coeffs(table(a, b), spec));
    if (!coeffs_.empty()) uniform_ = broadcast(0);  // a scene without materials has no contacts
    b_.width = wb_.width = W;
  }
  std::span<const HistorySlot> history_slots() const override { return slots_; }

  void evaluate(ParticleStore& p, const Walls& walls, PairList& pl, WallPairList& wl, double dt,
                EvaluationTotals& tot, std::vector<WallLoad>& loads) override {
    prefetch_scatter_ = p.size() >= kScatterPrefetchFrom;
    tot = EvaluationTotals{};
    released_ = 0.0;
    if constexpr (kFlagsTests) tests_due_.clear();
    if constexpr (kTrackRelease) {
      if (rescan_) find_live(pl, wl);
      next_live_pairs_.clear();
      next_live_walls_.clear();
    }
    pair_contacts(p, pl, dt, tot);
    wall_contacts(p, walls, wl, dt, tot, loads);
    if constexpr (kTrackRelease) release_ended(p, walls, pl, wl, dt);
    tot.dissipated += released_;
  }
  void committed() override {
    live_pairs_.swap(next_live_pairs_);
    live_walls_.swap(next_live_walls_);
  }
  void lists_changed() override { rescan_ = true; }
  bool histories_in_place() const override { return kInPlace; }
  std::span<const std::int32_t> breakage_tests_due() const override { return tests_due_; }
  PairKinematics* drift_mirror(const ParticleStore& p) override {
#if DEM2D_VECTOR_GATHER
    if (vector_gather_) {
      kin_.expect_owned(p.layout());
      return kin_.lines(p.n_owned());
    }
#endif
    static_cast<void>(p);
    return nullptr;
  }

 private:
  // The model's slots, then the shape's.
  static std::vector<HistorySlot> all_slots() {
    std::vector<HistorySlot> out = Model::history_slots();
    out.insert(out.end(), Shape::kHistory.begin(), Shape::kHistory.end());
    return out;
  }
  typename Model::template Coeffs<Pack> broadcast(std::int32_t k) const {
    return Model::broadcast(coeffs_[k]);
  }
  template <class Index>
  [[gnu::always_inline]] typename Model::template Coeffs<Pack> coeffs_of(Index index) const {
    if (n_mat_ == 1) return uniform_;
    return Model::gather(coeffs_.data(), index);
  }

  // The contact model on the pack of contacts [c, c + kPackSize) of a batch: coefficients of
  // each lane's material pair, the history read from the batch and the advanced one written
  // back. The one evaluation both paths share.
  template <class Batch>
  [[gnu::always_inline]] ContactResponseT<Pack> respond(Batch& batch, std::size_t c,
                                                        const KinematicsT<Pack>& kin,
                                                        double dt) const {
    typename Model::template History<Pack> h;
    const auto pc = coeffs_of([&](auto l) { return batch.coeff[c + l]; });
    const ContactResponseT<Pack> out =
        Model::evaluate(pc, kin, load_history<Model>(batch.history, c), h, dt);
    store_history<Model>(h, batch.history, c);
    return out;
  }

  // What a pair loop adds up as it goes (pair_contacts).
  struct PairTotals {
    EightLanes dissipated, elastic;
    double max_ratio = 0.0;
    std::int64_t contacts = 0, worst_a = -1, worst_b = -1;
    void into(EvaluationTotals& tot) const {
      tot.contacts += contacts;
      tot.dissipated = dissipated.sum();
      tot.elastic = elastic.sum();
      tot.max_overlap = max_ratio;
      tot.worst_a = worst_a;
      tot.worst_b = worst_b;
    }
  };
  static constexpr std::size_t kChunk = 512;
  void prepare_pairs(ParticleStore& p, PairList& pl);
  void pair_chunk(ParticleStore& p, PairList& pl, std::size_t k0, std::size_t k1, double dt,
                  PairTotals& t);
  void pair_contacts(ParticleStore& p, PairList& pl, double dt, EvaluationTotals& tot);
  std::size_t gather_pairs(const ParticleStore& p, PairList& pl, std::size_t k0, std::size_t k1);
  void gather_rotations_axes(const PairList& pl, std::size_t n);
  void remember_axes(const PairList& pl, std::size_t n);
  void find_live(const PairList& pl, const WallPairList& wl);
  void release_ended(const ParticleStore& p, const Walls& walls, const PairList& pl,
                     const WallPairList& wl, double dt);
  static bool holds_energy(const double* h) {
    bool any = false;
    for (std::size_t s = 0; s < kSpringSlots; ++s) any |= h[s] != 0.0;
    return any;
  }
  void release_pair(const ParticleStore& p, std::int32_t i, std::int32_t j, double dt,
                    const double* h);
  void release_wall(const ParticleStore& p, const Walls& walls, std::int32_t i,
                    std::int32_t element, double dt, const double* h);
  void evaluate_pairs(std::size_t n, double dt, EightLanes& dissipated, EightLanes& elastic,
                      Pack& overlap);
  static KinematicsT<Pack> pair_kinematics(const PairContactT<Pack>& g, Pack mi, Pack mj, Pack ri,
                                           Pack rj);
  void evaluate_pairs_apart(std::size_t n, double dt, EightLanes& dissipated, EightLanes& elastic,
                            Pack& overlap);
  // What one pack of pairs hands to the batch (put_pack).
  struct PackOut {
    Pack fx, fy, ti, tj, diss, el, ratio, ex, ey;
    Pack eti, etj;  // the elastic normal force's torques on i and j (arms apart; else unused)
  };
  void put_pack(std::size_t c, std::size_t n, const PackOut& o, EightLanes& dissipated,
                EightLanes& elastic, Pack& overlap);
  void scatter_pairs(ParticleStore& p, PairList& pl, std::size_t n);
  void note_tests_due(std::size_t n);
  void write_records(PairList& pl, std::size_t n);
  // Where the scatter writes the contacts' new histories: over the committed ones (kInPlace) or
  // into the trial slots.
  static double* new_histories(PairList& pl) {
    return kInPlace ? pl.history.data() : pl.trial.data();
  }
  void sum_records(ParticleStore& p, const PairList& pl);
  void wall_contacts(ParticleStore& p, const Walls& walls, WallPairList& wl, double dt,
                     EvaluationTotals& tot, std::vector<WallLoad>& loads);
  // The wall entries in list order, their histories read from the committed slots and rewritten
  // into the trial slots.
  std::size_t gather_walls(const ParticleStore& p, const Walls& walls, WallPairList& wl);
  std::size_t put_wall(std::size_t n, std::size_t k, std::int32_t i, std::int32_t coeff,
                       const WallGeometry& g, Vec2 vrel, Vec2 vw, double omega_rel,
                       const ParticleStore& p, const double* old);
  void evaluate_walls(std::size_t n, double dt);
  // Forces, energies and histories of the wall contacts; one load record each into `loads`.
  void scatter_walls(ParticleStore& p, WallPairList& wl, std::size_t n, EvaluationTotals& tot,
                     std::vector<WallLoad>& loads);

  int n_mat_;
  std::vector<Coeffs> coeffs_;  // [a * n_mat_ + b]
  typename Model::template Coeffs<Pack> uniform_;
  std::vector<HistorySlot> slots_;
  // The slots that hold spring energy (law and rolling), and the energy released this
  // evaluation by contacts that ended (J, this rank's share).
  static constexpr std::size_t kSpringSlots = Model::kLawSlots + Model::kRollingSlots;
  // Tracked only where the springs' stiffness stays finite as the overlap goes to zero (linear
  // law): with a Hertz stiffness what a contact holds in its last step vanishes with dt (nil to
  // 4 digits in the waterfall's balance), and tracking it cost 3-6 % of the run time.
  static constexpr bool kTrackRelease = kSpringSlots > 0 && !Model::Law::kStiffnessVanishes;
  // The pairs' new histories written over the committed ones (ContactKernel::histories_in_place)
  // where nothing reads the committed ones after the evaluation: not with release tracking
  // (release_ended), a tracker (the collision spectra read both) or the iterative scheme (its
  // passes all start from the committed histories).
  static constexpr bool kInPlace = !kTrackRelease &&
                                   std::is_same_v<typename Model::Tracker, TrackNone> &&
                                   std::is_same_v<typename Model::Stepper, StepAsSeen>;
  double released_ = 0.0;
  // With the breakage tracker, the entries whose test is due (breakage_tests_due): found in the
  // chunks' new histories, where the grinding's scan of every entry's history after the step
  // had cost 7 % of the grinding deck's time.
  static constexpr bool kFlagsTests = std::is_same_v<typename Model::Tracker, TrackBreakage>;
  std::vector<std::int32_t> tests_due_;
  // The list entries in contact in the committed histories (the only ones that can end in this
  // step), and those in contact in this evaluation (committed next). After a rebuild they are
  // found again from the histories (rescan_).
  std::vector<std::int32_t> live_pairs_, live_walls_, next_live_pairs_, next_live_walls_;
  std::vector<std::uint8_t> marks_;  // all zero between evaluations
  bool rescan_ = true;
  ContactBatch b_;
  Array<std::int32_t> bi_, bj_;  // the batch's particles (local indices)
  bool vector_gather_;
#if DEM2D_VECTOR_GATHER
  KinematicsMirror kin_;  // the vector gather's mirror of the particles
#endif
  WallBatch wb_;
  // With the list in storage order: per entry, in contact in this evaluation; per entry, the
  // force, torque and elastic force on i (2k) and on j (2k + 1).
  struct ForceRecord {
    double fx, fy, t, ex, ey;
  };
  Array<std::uint8_t> touch_;
  Array<ForceRecord> records_;
  // Beside them, for a shape whose arms leave the normal: the elastic normal force's torque on
  // i (2k) and on j (2k + 1) (else never sized).
  Array<double> elastic_torque_records_;
  bool prefetch_scatter_ = false;  // scatter_pairs fetches the partners' lines ahead
  // With kSemiAxes: each batch contact's a_i, b_i, n_i, a_j, b_j, n_j, then cos and sin of
  // theta_i and theta_j, then the separating axis remembered for the pair (axes_; zero: none)
  // (else never sized).
  std::array<Array<double>, 12> forms_;
  // With kSemiAxes: each body's cos and sin of its angle, taken once per force evaluation (the
  // same functions of the same angle as the shape's own, so the same bits).
  Array<double> rot_cos_, rot_sin_;
  // With kSemiAxes: per pair-list entry, the separating axis the shape found at the entry's last
  // evaluation apart (zero: none), with the pair's ids (an entry whose ids differ, after a
  // rebuild, holds none). The shape uses it only to prove a pair apart faster, never for a
  // contact, so nothing computed depends on it: it is neither migrated nor checkpointed.
  struct AxisMemo {
    std::int64_t id_i = -1, id_j = -1;
    double x = 0.0, y = 0.0;
  };
  std::vector<AxisMemo> axes_;
  // The batch's separating axes out of the shape (kSemiAxes).
  std::array<Array<double>, 2> axis_out_;
  // Body i's form for the shape's wall (kSemiAxes).
  static SuperEllipse form_of(const ParticleStore& p, std::size_t i) {
    return {(*p.semi_a())[i], (*p.semi_b())[i], (*p.exponent())[i]};
  }
};

}  // namespace dem2d::kernels
