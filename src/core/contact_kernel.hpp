// The force kernel of one contact model (ContactModel<Law, Rolling, Tracker, Stepper>): the
// gather, evaluate and scatter phases of contact_batch.hpp for particle pairs and particle-wall
// contacts, and the factory of one law's kernels. Included only by the kernels_*.cpp files, one
// per contact law, so that the laws' kernels compile in parallel (36 instantiations in one file
// took over 6 minutes under the sanitizers); contact_engine.cpp picks the law.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <tuple>
#include <type_traits>
#include <vector>

#include "core/contact_batch.hpp"
#include "core/contact_engine.hpp"
#include "core/contact_models.hpp"
#include "core/disc.hpp"
#include "core/pair_gather.hpp"

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

// The force loop for one contact model (docs/architecture.md, "Code conventions": written once, the model chosen at
// setup). Particle-particle contacts in canonical (lower id first, sorted) order, in chunks,
// then particle-wall contacts; each in the three phases of contact_batch.hpp. Both paths call
// Model::evaluate for the physics; they differ only in the geometry they gather and in what
// they scatter.
template <class Model>
class Kernel final : public ContactKernel {
  // The particle shape's narrow phase and inertia (core/disc.hpp); the gather is the disc's.
  using Shape = Disc;
  static_assert(Shape::kArmsAlongNormal,
                "the torques and surface velocities below take arms along n");
  using Coeffs = typename Model::template Coeffs<double>;
  static constexpr std::size_t W = Model::kHistoryWidth;
  static_assert(W <= kMaxHistorySlots, "raise kMaxHistorySlots");

 public:
  Kernel(const ContactSpec& spec, const PairTable& table)
      : n_mat_(table.n_materials()),
        slots_(Model::history_slots()),
        vector_gather_(kHaveVectorGather && !spec.scalar_gather) {
    for (int a = 0; a < n_mat_; ++a)
      for (int b = 0; b < n_mat_; ++b) coeffs_.push_back(Model::coeffs(table(a, b), spec));
    if (!coeffs_.empty()) uniform_ = broadcast(0);  // a scene without materials has no contacts
    b_.width = wb_.width = W;
  }
  std::span<const HistorySlot> history_slots() const override { return slots_; }

  void evaluate(ParticleStore& p, const Walls& walls, PairList& pl, WallPairList& wl, double dt,
                EvaluationTotals& tot) override {
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
    wall_contacts(p, walls, wl, dt, tot);
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
                     EvaluationTotals& tot);
  // The wall entries in list order, their histories read from the committed slots and rewritten
  // into the trial slots.
  std::size_t gather_walls(const ParticleStore& p, const Walls& walls, WallPairList& wl);
  void evaluate_walls(std::size_t n, double dt);
  void scatter_walls(ParticleStore& p, const Walls& walls, WallPairList& wl, std::size_t n,
                     EvaluationTotals& tot);

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
  bool prefetch_scatter_ = false;  // scatter_pairs fetches the partners' lines ahead
};

// The candidates are processed in chunks, each through phases A, B and C, so that the batch
// arrays stay in the L1/L2 cache (one pass over a batch of every contact streamed 20 arrays
// through memory: 1.7x slower per particle-step at 1e5 particles). Chunks run in list order, so
// the scatter stays canonical.
template <class Model>
void Kernel<Model>::prepare_pairs([[maybe_unused]] ParticleStore& p, PairList& pl) {
  b_.reserve(kChunk + kPackSize);
  if (bi_.size() < kChunk + kPackSize) {
    bi_.resize(kChunk + kPackSize);
    bj_.resize(kChunk + kPackSize);
  }
#if DEM2D_VECTOR_GATHER
  if (vector_gather_) {
    fill_kinematics(kin_.lines(p.size()), p.pos.data(), p.vel.data(), p.omega.data(),
                    p.radius.data(), p.mass.data(), p.material.data(),
                    kin_.fresh_lines(p.layout(), p.n_owned()), p.size());
  }
#endif
  if (!pl.canonical() && touch_.size() != pl.size()) {
    touch_.assign(pl.size(), 0);
    records_.resize(2 * pl.size());
  }
}

// Candidates [k0, k1): phases A, B and C.
template <class Model>
[[gnu::always_inline]] inline void Kernel<Model>::pair_chunk(ParticleStore& p, PairList& pl,
                                                             std::size_t k0, std::size_t k1,
                                                             double dt, PairTotals& t) {
  const std::size_t n = gather_pairs(p, pl, k0, k1);
  Pack chunk_overlap(0.0);
  evaluate_pairs(n, dt, t.dissipated, t.elastic, chunk_overlap);
  scatter_pairs(p, pl, n);
  // The chunk's contacts, for release_ended next step (out of the scatter loop: a push_back
  // there cost 7 % on the waterfall).
  if constexpr (kTrackRelease)
    next_live_pairs_.insert(next_live_pairs_.end(), b_.pair.data(), b_.pair.data() + n);
  if constexpr (kFlagsTests) note_tests_due(n);
  // Counted apart from the scatter: this loop vectorises, the scatter cannot.
  for (std::size_t c = 0; c < n; ++c) t.contacts += b_.counted[c] > 0.5 ? 1 : 0;
  // The first pair at the largest overlap so far names the culprits of a blow-up.
  const double chunk_max = stdx::hmax(chunk_overlap);
  if (chunk_max > kMaxOverlapRatio && chunk_max > t.max_ratio) {
    for (std::size_t c = 0; c < n; ++c)
      if (b_.overlap[c] == chunk_max) {
        t.worst_a = p.id[pl.i[b_.pair[c]]];
        t.worst_b = p.id[pl.j[b_.pair[c]]];
        break;
      }
  }
  t.max_ratio = std::max(t.max_ratio, chunk_max);
}

template <class Model>
void Kernel<Model>::pair_contacts(ParticleStore& p, PairList& pl, double dt,
                                  EvaluationTotals& tot) {
  prepare_pairs(p, pl);
  PairTotals t;
  for (std::size_t k0 = 0; k0 < pl.size(); k0 += kChunk)
    pair_chunk(p, pl, k0, std::min(pl.size(), k0 + kChunk), dt, t);
  if (!pl.canonical()) sum_records(p, pl);
  t.into(tot);
}

// A contact that ended in this step releases the energy its springs held at the end of the last
// step, at the overlap then: booked as dissipated (docs/output.md). Rare: out of line.
template <class Model>
[[gnu::noinline]] void Kernel<Model>::release_pair(const ParticleStore& p, std::int32_t i,
                                                   std::int32_t j, double dt, const double* h) {
  if (static_cast<std::size_t>(i) >= p.n_owned()) return;  // booked where i is owned
  // x_j - x_i a step ago: before the drift dt v (Verlet: exactly the drift just taken).
  const Vec2 d_old = (p.pos[j] - p.pos[i]) - dt * (p.vel[j] - p.vel[i]);
  const double ri = p.radius[i], rj = p.radius[j];
  const double delta_old = ri + rj - norm(d_old);
  const auto& c = coeffs_[p.material[i] * n_mat_ + p.material[j]];
  released_ += Model::spring_energy(c, ri * rj / (ri + rj), delta_old, h);
}

template <class Model>
[[gnu::noinline]] void Kernel<Model>::release_wall(const ParticleStore& p, const Walls& walls,
                                                   std::int32_t i, std::int32_t element, double dt,
                                                   const double* h) {
  const WallGeometry g = Disc::wall(walls, element, p.pos[i], p.radius[i]);
  const WallElement& e = walls.elements()[element];
  const Vec2 v_rel = p.vel[i] - walls.velocity_at(e.body, g.point);
  const double delta_old = g.delta - dt * dot(v_rel, g.n);  // closing along n, from i to the wall
  const auto& c = coeffs_[p.material[i] * n_mat_ + e.material];
  released_ += Model::spring_energy(c, p.radius[i], delta_old, h);
}

// The entries whose committed history holds spring energy (after a rebuild: rare).
template <class Model>
void Kernel<Model>::find_live(const PairList& pl, const WallPairList& wl) {
  live_pairs_.clear();
  live_walls_.clear();
  for (std::size_t k = 0; k < pl.size(); ++k)
    if (holds_energy(pl.history.data() + k * W))
      live_pairs_.push_back(static_cast<std::int32_t>(k));
  for (std::size_t k = 0; k < wl.size(); ++k)
    if (holds_energy(wl.history.data() + k * W))
      live_walls_.push_back(static_cast<std::int32_t>(k));
  rescan_ = false;
}

// The contacts of the committed state that are not in contact in this evaluation release what
// their springs held (marks over the list entries: no geometry recomputed, no search).
template <class Model>
void Kernel<Model>::release_ended(const ParticleStore& p, const Walls& walls, const PairList& pl,
                                  const WallPairList& wl, double dt) {
  const auto ended = [&](const std::vector<std::int32_t>& before,
                         const std::vector<std::int32_t>& now, std::size_t size, auto release) {
    if (before.empty()) return;
    if (marks_.size() < size) marks_.resize(size, 0);
    for (const std::int32_t k : now) marks_[k] = 1;
    for (const std::int32_t k : before)
      if (!marks_[k]) release(k);
    for (const std::int32_t k : now) marks_[k] = 0;
  };
  ended(live_pairs_, next_live_pairs_, pl.size(), [&](std::int32_t k) {
    const double* h = pl.history.data() + static_cast<std::size_t>(k) * W;
    if (holds_energy(h)) release_pair(p, pl.i[k], pl.j[k], dt, h);
  });
  ended(live_walls_, next_live_walls_, wl.size(), [&](std::int32_t k) {
    const double* h = wl.history.data() + static_cast<std::size_t>(k) * W;
    if (holds_energy(h)) release_wall(p, walls, wl.particle[k], wl.element[k], dt, h);
  });
}

// A. Gather the pairs in contact among candidates [k0, k1) (core/pair_gather.hpp); pairs apart
// lose their history (what their springs held is released: release_ended).
template <class Model>
std::size_t Kernel<Model>::gather_pairs(const ParticleStore& p, PairList& pl, std::size_t k0,
                                        std::size_t k1) {
  if constexpr (!kInPlace)  // the scatter rewrites the contacts'
    std::fill(pl.trial.data() + k0 * W, pl.trial.data() + k1 * W, 0.0);
  std::array<double*, W + 1> old{};  // W may be 0
  for (std::size_t s = 0; s < W; ++s) old[s] = b_.history.old[s].data();
  const GatherColumns cols{.x = p.pos.data(),
                           .v = p.vel.data(),
                           .w = p.omega.data(),
                           .r = p.radius.data(),
                           .m = p.mass.data(),
                           .material = p.material.data(),
                           .li = pl.i.data(),
                           .lj = pl.j.data(),
                           .entries = pl.size(),
                           .history = pl.history.data(),
                           .width = W,
                           .n_owned = p.n_owned(),
                           .n_mat = n_mat_,
                           .pair = b_.pair.data(),
                           .bi = bi_.data(),
                           .bj = bj_.data(),
                           .coeff = b_.coeff.data(),
                           .counted = b_.counted.data(),
                           .dx = b_.dx.data(),
                           .dy = b_.dy.data(),
                           .dist2 = b_.dist2.data(),
                           .r_i = b_.r_i.data(),
                           .r_j = b_.r_j.data(),
                           .m_i = b_.m_i.data(),
                           .m_j = b_.m_j.data(),
                           .vx = b_.vx.data(),
                           .vy = b_.vy.data(),
                           .spin = b_.spin.data(),
                           .omega_rel = b_.omega_rel.data(),
                           .old = old.data()};
  std::size_t n = 0;
#if DEM2D_VECTOR_GATHER
  if (vector_gather_) n = gather_contacts_vector<W>(kin_.data(), cols, k0, k1);
#endif
  if (!vector_gather_) n = find_contacts_scalar(cols, k0, k1);
  if (!pl.canonical()) {  // apart from the loop above: a byte store there aliases everything
    std::uint8_t* touch = touch_.data();
    std::fill(touch + k0, touch + k1, std::uint8_t{0});
    for (std::size_t c = 0; c < n; ++c) touch[b_.pair[c]] = 1;
  }
  if (!vector_gather_ && n > 0) gather_inputs_scalar(cols, 0, n);
  // In place: the committed histories of the chunk are read; the scatter rewrites the contacts'.
  if constexpr (kInPlace) std::fill(pl.history.data() + k0 * W, pl.history.data() + k1 * W, 0.0);
  if (n == 0) return 0;
  // Padding lanes repeat the last contact.
  for (std::size_t c = n; c < padded(n); ++c) {
    b_.copy(c, n - 1);
    bi_[c] = bi_[n - 1];
    bj_[c] = bj_[n - 1];
  }
  return n;
}

// B. The contact model on packs of kPackSize contacts.
template <class Model>
void Kernel<Model>::evaluate_pairs(std::size_t n, double dt, EightLanes& dissipated,
                                   EightLanes& elastic, Pack& overlap) {
  for (std::size_t c = 0; c < padded(n); c += kPackSize) {
    const Pack ri = load(b_.r_i, c), rj = load(b_.r_j, c);
    const PairContactT<Pack> g =
        Shape::pair(load(b_.dx, c), load(b_.dy, c), load(b_.dist2, c), ri, rj);
    const Pack nx = g.nx, ny = g.ny;
    const Pack tx = -ny, ty = nx;
    const Pack mi = load(b_.m_i, c), mj = load(b_.m_j, c);
    KinematicsT<Pack> kin;
    kin.delta = g.delta;
    kin.r_eff = g.r_eff;
    kin.m_eff = mi * mj / (mi + mj);
    if constexpr (Model::Rolling::kNeedsInertia) {
      // About the contact point; harmonic mean of the two bodies.
      const Pack ia = Shape::contact_inertia(mi, ri), ib = Shape::contact_inertia(mj, rj);
      kin.i_eff = ia * ib / (ia + ib);
    }
    const Pack spin = load(b_.spin, c);
    project_velocity(kin, load(b_.vx, c) + spin * tx, load(b_.vy, c) + spin * ty, nx, ny);
    kin.omega_rel = load(b_.omega_rel, c);
    const ContactResponseT<Pack> out = respond(b_, c, kin, dt);
    const ContactForceT<Pack>& cf = out.law;
    const Pack fx = cf.f_t * tx - cf.f_n * nx, fy = cf.f_t * ty - cf.f_n * ny;
    // Arms along the normal (Shape::kArmsAlongNormal): arm x force = arm f_t.
    const Pack arm_i = Model::Law::kTorqueArmIsReff ? kin.r_eff : g.arm_i;
    const Pack arm_j = Model::Law::kTorqueArmIsReff ? kin.r_eff : g.arm_j;
    Pack ti = arm_i * cf.f_t, tj = arm_j * cf.f_t;
    Pack diss = cf.dissipated, el = cf.elastic;
    if constexpr (Model::Rolling::kActive) {
      ti += out.rolling.torque;
      tj -= out.rolling.torque;
      diss += out.rolling.dissipated;
      el += out.rolling.elastic;
    }
    Pack ratio = kin.delta / vmin(ri, rj);
    if constexpr (Model::Tracker::kExcludes)  // a birth overlap is not the guard's concern
      ratio = (kin.delta - out.birth_overlap) / vmin(ri, rj);
    // Padding lanes repeat the last contact: keep them out of the sums.
    const PackMask real =
        Pack([&](auto l) { return static_cast<double>(c + l); }) < static_cast<double>(n) &&
        load(b_.counted, c) > 0.5;
    dissipated.add(c, select(real, diss, Pack(0.0)));
    elastic.add(c, select(real, el, Pack(0.0)));
    overlap = vmax(overlap, ratio);
    store(fx, b_.fx, c);
    store(fy, b_.fy, c);
    store(ti, b_.t_i, c);
    store(tj, b_.t_j, c);
    store(ratio, b_.overlap, c);
    store(-cf.f_el * nx, b_.ex, c);
    store(-cf.f_el * ny, b_.ey, c);
  }
}

// C. Scatter in canonical pair order; or, with the list in storage order, the two force records
// of each contact (sum_records adds them up in canonical order).
template <class Model>
void Kernel<Model>::scatter_pairs(ParticleStore& p, PairList& pl, std::size_t n) {
  if (!pl.canonical()) return write_records(pl, n);
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  Vec2* f_el = p.elastic_force.data();
  double* trial = new_histories(pl);
  const std::int32_t* bj = bj_.data();
  // The partner's three lines kAhead contacts ahead (the lower-id particles come in order), where
  // the store is past the caches: at 1e5 particles the scatter waited on them (whole run 0.94x
  // with the prefetch), at 3e4 the prefetch cost 4 % (bench/throughput, paired runs).
  constexpr std::size_t kAhead = 16;
  const std::size_t ahead = prefetch_scatter_ ? kAhead : n;
  for (std::size_t c = 0; c < n; ++c) {
    if (c + ahead < n) {
      const std::int32_t next = bj[c + ahead];
      __builtin_prefetch(f + next, 1);
      __builtin_prefetch(tq + next, 1);
      __builtin_prefetch(f_el + next, 1);
    }
    const std::int32_t k = b_.pair[c];
    const std::int32_t i = bi_[c], j = bj[c];
    const Vec2 fi{b_.fx[c], b_.fy[c]};
    f[i] += fi;
    f[j] -= fi;
    tq[i] += b_.t_i[c];
    tq[j] += b_.t_j[c];
    const Vec2 ei{b_.ex[c], b_.ey[c]};
    f_el[i] += ei;
    f_el[j] -= ei;
    for (std::size_t s = 0; s < W; ++s)
      trial[static_cast<std::size_t>(k) * W + s] = b_.history.fresh[s][c];
  }
}

// The chunk's contacts whose breakage test is due, by their new histories (the values the
// commit makes the committed ones), in list order.
template <class Model>
void Kernel<Model>::note_tests_due(std::size_t n) {
  constexpr std::size_t kTracker = Model::kLawSlots + Model::kRollingSlots;
  const double* peak = b_.history.fresh[kTracker + TrackBreakage::kPeak].data();
  const double* energy = b_.history.fresh[kTracker + TrackBreakage::kEnergy].data();
  const double* tested = b_.history.fresh[kTracker + TrackBreakage::kTested].data();
  for (std::size_t c = 0; c < n; ++c)
    if (TrackBreakage::test_due(peak[c], energy[c], tested[c])) tests_due_.push_back(b_.pair[c]);
}

template <class Model>
void Kernel<Model>::write_records(PairList& pl, std::size_t n) {
  double* trial = new_histories(pl);
  ForceRecord* rec = records_.data();
  for (std::size_t c = 0; c < n; ++c) {
    const std::size_t k = static_cast<std::size_t>(b_.pair[c]);
    rec[2 * k] = {b_.fx[c], b_.fy[c], b_.t_i[c], b_.ex[c], b_.ey[c]};
    rec[2 * k + 1] = {-b_.fx[c], -b_.fy[c], b_.t_j[c], -b_.ex[c], -b_.ey[c]};
    for (std::size_t s = 0; s < W; ++s) trial[k * W + s] = b_.history.fresh[s][c];
  }
}

// Each owned particle's pair forces added in the order of its partners' ids, as the canonical
// scatter adds them (f - g and f + (-g) are the same number); the records of candidates not in
// contact are passed over (they hold an earlier evaluation's values).
template <class Model>
void Kernel<Model>::sum_records(ParticleStore& p, const PairList& pl) {
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  Vec2* f_el = p.elastic_force.data();
  const ForceRecord* rec = records_.data();
  const std::uint8_t* touch = touch_.data();
  const std::int32_t* index = pl.records.data();
  const std::size_t n_owned = pl.record_start.size() - 1;
  for (std::size_t q = 0; q < n_owned; ++q) {
    Vec2 fq = f[q], eq = f_el[q];
    double tq_q = tq[q];
    for (std::int32_t s = pl.record_start[q]; s < pl.record_start[q + 1]; ++s) {
      const std::int32_t r = index[s];
      const ForceRecord& g = rec[r];
      // Selects, not a branch: whether a candidate touches is close to random.
      const bool on = touch[r >> 1] != 0;
      fq = on ? fq + Vec2{g.fx, g.fy} : fq;
      tq_q = on ? tq_q + g.t : tq_q;
      eq = on ? eq + Vec2{g.ex, g.ey} : eq;
    }
    f[q] = fq;
    tq[q] = tq_q;
    f_el[q] = eq;
  }
}

// Walls: R* = r_i, m* = m_i; the wall's velocity at the contact point enters v_rel. The same
// three phases as the particle pairs, in one batch.
template <class Model>
void Kernel<Model>::wall_contacts(ParticleStore& p, const Walls& walls, WallPairList& wl, double dt,
                                  EvaluationTotals& tot) {
  wb_.reserve(wl.size() + kPackSize);
  const std::size_t n = gather_walls(p, walls, wl);
  evaluate_walls(n, dt);
  scatter_walls(p, walls, wl, n, tot);
  if constexpr (kTrackRelease)
    next_live_walls_.insert(next_live_walls_.end(), wb_.pair.data(), wb_.pair.data() + n);
  tot.contacts += static_cast<std::int64_t>(n);
}

template <class Model>
std::size_t Kernel<Model>::gather_walls(const ParticleStore& p, const Walls& walls,
                                        WallPairList& wl) {
  const double* old = wl.history.data();
  double* fresh = wl.trial.data();
  const Vec2* x = p.pos.data();
  const Vec2* v = p.vel.data();
  const double* w = p.omega.data();
  const double* r = p.radius.data();
  const std::int32_t* mat = p.material.data();
  const WallElement* elements = walls.elements().data();
  const WallBody* bodies = walls.bodies().data();
  std::size_t n = 0;
  for (std::size_t k = 0; k < wl.size(); ++k) {
    const std::int32_t i = wl.particle[k];
    for (std::size_t s = 0; s < W; ++s) fresh[k * W + s] = 0.0;  // the scatter rewrites contacts
    const WallElement& e = elements[wl.element[k]];
    WallGeometry g;
    if (e.kind == WallKind::kCircle) {
      // The circle's test and geometry of Disc::touches_wall and Disc::wall, with the cheap
      // test's distance kept for the geometry.
      const Vec2 c = walls.circle_center(e);
      const Vec2 d = x[i] - c;
      const double d2 = norm2(d);
      if (Disc::clear_inside_circle(e.radius, r[i], d2)) continue;
      g = Disc::inside_circle(c, e.radius, d, std::sqrt(d2), r[i]);
    } else {
      // Most candidates do not touch: the cheap test skips the square root and division of the
      // full geometry (5 % of the waterfall's time, measured A/B with bench/throughput).
      if (!Disc::touches_wall(walls, wl.element[k], x[i], r[i])) continue;
      g = Disc::wall(walls, wl.element[k], x[i], r[i]);
    }
    if (g.delta <= 0.0) continue;  // the cheap test and the geometry may differ in the last bit
    const Vec2 vw = walls.velocity_at(e.body, g.point);
    const Vec2 vrel = (v[i] - vw) + (w[i] * r[i]) * perp(g.n);
    wb_.pair[n] = static_cast<std::int32_t>(k);
    wb_.coeff[n] = mat[i] * n_mat_ + e.material;
    wb_.delta[n] = g.delta;
    wb_.nx[n] = g.n.x;
    wb_.ny[n] = g.n.y;
    wb_.r[n] = r[i];
    wb_.m[n] = p.mass[i];
    wb_.vx[n] = vrel.x;
    wb_.vy[n] = vrel.y;
    wb_.omega_rel[n] = w[i] - bodies[e.body].omega;
    for (std::size_t s = 0; s < W; ++s) wb_.history.old[s][n] = old[k * W + s];
    wb_.wx[n] = vw.x;
    wb_.wy[n] = vw.y;
    wb_.px[n] = g.point.x;
    wb_.py[n] = g.point.y;
    ++n;
  }
  for (std::size_t c = n; c < padded(n); ++c) wb_.copy(c, n - 1);
  return n;
}

template <class Model>
void Kernel<Model>::evaluate_walls(std::size_t n, double dt) {
  for (std::size_t c = 0; c < padded(n); c += kPackSize) {
    const Pack nx = load(wb_.nx, c), ny = load(wb_.ny, c);
    const Pack tx = -ny, ty = nx;
    const Pack ri = load(wb_.r, c), mi = load(wb_.m, c);
    KinematicsT<Pack> kin;
    kin.delta = load(wb_.delta, c);
    kin.r_eff = ri;
    kin.m_eff = mi;
    if constexpr (Model::Rolling::kNeedsInertia) kin.i_eff = Shape::contact_inertia(mi, ri);
    project_velocity(kin, load(wb_.vx, c), load(wb_.vy, c), nx, ny);
    kin.omega_rel = load(wb_.omega_rel, c);
    const ContactResponseT<Pack> out = respond(wb_, c, kin, dt);
    const ContactForceT<Pack>& cf = out.law;
    const Pack fx = cf.f_t * tx - cf.f_n * nx, fy = cf.f_t * ty - cf.f_n * ny;
    Pack ti = ri * cf.f_t;
    if constexpr (Model::Rolling::kActive) ti += out.rolling.torque;
    store(fx, wb_.fx, c);
    store(fy, wb_.fy, c);
    store(ti, wb_.torque, c);
    store(out.rolling.torque, wb_.m_roll, c);
    store(cf.dissipated, wb_.diss_law, c);
    store(cf.elastic, wb_.el_law, c);
    store(out.rolling.dissipated, wb_.diss_roll, c);
    store(out.rolling.elastic, wb_.el_roll, c);
    store(-cf.f_el * nx, wb_.ex, c);
    store(-cf.f_el * ny, wb_.ey, c);
    if constexpr (Model::Tracker::kExcludes)  // a birth overlap is not the guard's concern
      store(kin.delta - out.birth_overlap, wb_.delta, c);
  }
}

template <class Model>
void Kernel<Model>::scatter_walls(ParticleStore& p, const Walls& walls, WallPairList& wl,
                                  std::size_t n, EvaluationTotals& tot) {
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  Vec2* f_el = p.elastic_force.data();
  const WallElement* elements = walls.elements().data();
  const WallBody* bodies = walls.bodies().data();
  const int drum = walls.drum_body();
  const Vec2 drum_center = walls.has_drum() ? bodies[drum].center : Vec2{};
  double dissipated = tot.dissipated, elastic = tot.elastic, max_ratio = tot.max_overlap;
  for (std::size_t c = 0; c < n; ++c) {
    const std::int32_t k = wb_.pair[c];
    const std::int32_t i = wl.particle[k];
    const WallElement& e = elements[wl.element[k]];
    const Vec2 fi{wb_.fx[c], wb_.fy[c]};
    const double m_roll = wb_.m_roll[c];
    f[i] += fi;
    tq[i] += wb_.torque[c];
    f_el[i] += Vec2{wb_.ex[c], wb_.ey[c]};
    dissipated += wb_.diss_law[c];
    elastic += wb_.el_law[c];
    if constexpr (Model::Rolling::kActive) {
      dissipated += wb_.diss_roll[c];
      elastic += wb_.el_roll[c];
    }
    for (std::size_t s = 0; s < W; ++s)
      wl.trial[static_cast<std::size_t>(k) * W + s] = wb_.history.fresh[s][c];
    // Power the wall's drive puts into the particles: F . v_wall + M Omega (the reaction couple).
    tot.drive_power += dot(fi, Vec2{wb_.wx[c], wb_.wy[c]}) + m_roll * bodies[e.body].omega;
    if (e.body == drum) {
      const double torque = cross(Vec2{wb_.px[c], wb_.py[c]} - drum_center, fi) + m_roll;
      tot.drum_torque += torque;
      if (e.part == WallPart::kLifter) tot.lifter_torque += torque;
    }
    const double ratio = wb_.delta[c] / wb_.r[c];
    if (ratio > max_ratio) {
      max_ratio = ratio;
      tot.worst_a = p.id[i];
      tot.worst_b = -1;
    }
  }
  tot.dissipated = dissipated;
  tot.elastic = elastic;
  tot.max_overlap = max_ratio;
}

// The stepper follows the integrator (contact_models.hpp, Steppers).
template <class Law, class Rolling, class Tracker>
std::unique_ptr<ContactKernel> make_kernel(const ContactSpec& spec, const PairTable& table,
                                           IntegratorKind integrator) {
  if (integrator == IntegratorKind::kIterative)
    return std::make_unique<Kernel<ContactModel<Law, Rolling, Tracker, StepTrapezoid>>>(spec,
                                                                                        table);
  return std::make_unique<Kernel<ContactModel<Law, Rolling, Tracker, StepAsSeen>>>(spec, table);
}

// The entry of a registry (a std::tuple of models) whose kKind is `kind`, handed to f as
// std::type_identity<Model>.
template <class Registry, class Kind, class F>
std::unique_ptr<ContactKernel> pick(Kind kind, F f) {
  return [&]<class... Models>(std::type_identity<std::tuple<Models...>>) {
    std::unique_ptr<ContactKernel> out;
    static_cast<void>(
        ((Models::kKind == kind ? (out = f(std::type_identity<Models>{}), true) : false) || ...));
    return out;
  }(std::type_identity<Registry>{});
}

// Every kernel of one law: its rolling models, trackers and steppers (rolling_kind: the one the
// scene runs, none when no pair has rolling friction).
template <class Law>
std::unique_ptr<ContactKernel> make_law_kernel(const ContactSpec& spec, const PairTable& table,
                                               RollingModelKind rolling_kind,
                                               IntegratorKind integrator) {
  return pick<RollingModels>(rolling_kind, [&](auto rolling) -> std::unique_ptr<ContactKernel> {
    using Rolling = typename decltype(rolling)::type;
    if (spec.track_breakage)
      return make_kernel<Law, Rolling, TrackBreakage>(spec, table, integrator);
    if (spec.track_peak_energy)
      return make_kernel<Law, Rolling, TrackPeakEnergy>(spec, table, integrator);
    return make_kernel<Law, Rolling, TrackNone>(spec, table, integrator);
  });
}

}  // namespace dem2d::kernels
