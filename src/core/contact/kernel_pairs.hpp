// The particle-pair contacts of the force kernel (Kernel<Model, Shape>, contact_kernel.hpp), in the
// three phases of contact_batch.hpp: A. gather the pairs in contact, B. evaluate the model on
// packs, C. scatter forces, torques and histories in canonical order.
#pragma once

#include <algorithm>
#include <stdexcept>

#include "core/contact/contact_kernel.hpp"

namespace dem2d::kernels {

// The candidates are processed in chunks, each through phases A, B and C, so that the batch
// arrays stay in the L1/L2 cache (one pass over a batch of every contact streamed 20 arrays
// through memory: 1.7x slower per particle-step at 1e5 particles). Chunks run in list order, so
// the scatter stays canonical.
template <class Model, class Shape>
void Kernel<Model, Shape>::prepare_pairs([[maybe_unused]] ParticleStore& p, PairList& pl) {
  b_.reserve(kChunk + kPackSize);
  if constexpr (kSemiAxes) {
    if (!p.shaped())
      throw std::logic_error("a shape with semi-axes needs the store's shape fields");
    if (forms_[0].size() < kChunk + kPackSize) {
      for (Array<double>& f : forms_) f.resize(kChunk + kPackSize);
      for (Array<double>& f : axis_out_) f.resize(kChunk + kPackSize);
    }
    const std::size_t bodies = p.size();
    if (rot_cos_.size() < bodies) {
      rot_cos_.resize(bodies);
      rot_sin_.resize(bodies);
    }
    const double* theta = p.theta.data();
    for (std::size_t i = 0; i < bodies; ++i) {
      const double t = theta[i];  // one load: the two calls become one sincos
      rot_cos_[i] = std::cos(t);
      rot_sin_[i] = std::sin(t);
    }
    if (axes_.size() != pl.size()) axes_.resize(pl.size());
  }
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
    if constexpr (kArmsApart) elastic_torque_records_.resize(2 * pl.size());
  }
}

// Candidates [k0, k1): phases A, B and C.
template <class Model, class Shape>
[[gnu::always_inline]] inline void Kernel<Model, Shape>::pair_chunk(ParticleStore& p, PairList& pl,
                                                                    std::size_t k0, std::size_t k1,
                                                                    double dt, PairTotals& t) {
  const std::size_t n = gather_pairs(p, pl, k0, k1);
  Pack chunk_overlap(0.0);
  evaluate_pairs(n, dt, t.dissipated, t.elastic, chunk_overlap);
  if constexpr (kSemiAxes) remember_axes(pl, n);
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

template <class Model, class Shape>
void Kernel<Model, Shape>::pair_contacts(ParticleStore& p, PairList& pl, double dt,
                                         EvaluationTotals& tot) {
  prepare_pairs(p, pl);
  PairTotals t;
  for (std::size_t k0 = 0; k0 < pl.size(); k0 += kChunk)
    pair_chunk(p, pl, k0, std::min(pl.size(), k0 + kChunk), dt, t);
  if (!pl.canonical()) sum_records(p, pl);
  t.into(tot);
}

// A. Gather the pairs in contact among candidates [k0, k1) (core/fast/pair_gather.hpp); pairs apart
// lose their history (what their springs held is released: release_ended).
template <class Model, class Shape>
std::size_t Kernel<Model, Shape>::gather_pairs(const ParticleStore& p, PairList& pl, std::size_t k0,
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
                           .old = old.data(),
                           .theta = kArmsApart ? p.theta.data() : nullptr,
                           .w_i = b_.w_i.data(),
                           .w_j = b_.w_j.data(),
                           .th_i = b_.th_i.data(),
                           .th_j = b_.th_j.data(),
                           .semi_a = kSemiAxes ? p.semi_a()->data() : nullptr,
                           .semi_b = kSemiAxes ? p.semi_b()->data() : nullptr,
                           .exponent = kSemiAxes ? p.exponent()->data() : nullptr,
                           .a_i = forms_[0].data(),
                           .b_i = forms_[1].data(),
                           .n_i = forms_[2].data(),
                           .a_j = forms_[3].data(),
                           .b_j = forms_[4].data(),
                           .n_j = forms_[5].data()};
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
  if constexpr (kArmsApart) gather_frames_scalar(cols, 0, n);
  if constexpr (kSemiAxes) gather_rotations_axes(pl, n);
  // In place: the committed histories of the chunk are read; the scatter rewrites the contacts'.
  if constexpr (kInPlace) std::fill(pl.history.data() + k0 * W, pl.history.data() + k1 * W, 0.0);
  if (n == 0) return 0;
  // Padding lanes repeat the last contact.
  for (std::size_t c = n; c < padded(n); ++c) {
    b_.copy(c, n - 1);
    bi_[c] = bi_[n - 1];
    bj_[c] = bj_[n - 1];
    if constexpr (kSemiAxes)
      for (Array<double>& f : forms_) f[c] = f[n - 1];
  }
  return n;
}

// The batch's rotations (each body's, from prepare_pairs) and remembered separating axes.
template <class Model, class Shape>
void Kernel<Model, Shape>::gather_rotations_axes(const PairList& pl, std::size_t n) {
  for (std::size_t c = 0; c < n; ++c) {
    const std::int32_t i = bi_[c], j = bj_[c];
    forms_[6][c] = rot_cos_[i];
    forms_[7][c] = rot_sin_[i];
    forms_[8][c] = rot_cos_[j];
    forms_[9][c] = rot_sin_[j];
    const auto k = static_cast<std::size_t>(b_.pair[c]);
    const AxisMemo& m = axes_[k];
    const bool same = m.id_i == pl.id_i[k] && m.id_j == pl.id_j[k];
    forms_[10][c] = same ? m.x : 0.0;
    forms_[11][c] = same ? m.y : 0.0;
  }
}

// The separating axes the shape found for the batch's pairs apart (zero for the others).
template <class Model, class Shape>
void Kernel<Model, Shape>::remember_axes(const PairList& pl, std::size_t n) {
  for (std::size_t c = 0; c < n; ++c) {
    const auto k = static_cast<std::size_t>(b_.pair[c]);
    axes_[k] = {pl.id_i[k], pl.id_j[k], axis_out_[0][c], axis_out_[1][c]};
  }
}

// A pair's overlap, R*, reduced mass and (rolling models) reduced inertia about the contact point:
// the harmonic mean of the two bodies'.
template <class Model, class Shape>
[[gnu::always_inline]] inline KinematicsT<Pack> Kernel<Model, Shape>::pair_kinematics(
    const PairContactT<Pack>& g, Pack mi, Pack mj, Pack ri, Pack rj) {
  KinematicsT<Pack> kin;
  kin.delta = g.delta;
  kin.r_eff = g.r_eff;
  kin.m_eff = mi * mj / (mi + mj);
  if constexpr (Model::Rolling::kNeedsInertia) {
    const Pack ia = Shape::contact_inertia(mi, ri), ib = Shape::contact_inertia(mj, rj);
    kin.i_eff = ia * ib / (ia + ib);
  }
  return kin;
}

// B. The contact model on packs of kPackSize contacts.
template <class Model, class Shape>
void Kernel<Model, Shape>::evaluate_pairs(std::size_t n, double dt, EightLanes& dissipated,
                                          EightLanes& elastic, Pack& overlap) {
  if constexpr (kArmsApart) {
    evaluate_pairs_apart(n, dt, dissipated, elastic, overlap);
  } else {
    for (std::size_t c = 0; c < padded(n); c += kPackSize) {
      const Pack ri = load(b_.r_i, c), rj = load(b_.r_j, c);
      const PairContactT<Pack> g =
          Shape::pair(load(b_.dx, c), load(b_.dy, c), load(b_.dist2, c), ri, rj);
      const Pack nx = g.nx, ny = g.ny;
      const Pack tx = -ny, ty = nx;
      KinematicsT<Pack> kin = pair_kinematics(g, load(b_.m_i, c), load(b_.m_j, c), ri, rj);
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
      put_pack(
          c, n,
          {fx, fy, ti, tj, diss, el, ratio, -cf.f_el * nx, -cf.f_el * ny, Pack(0.0), Pack(0.0)},
          dissipated, elastic, overlap);
    }
  }
}

// A pack's outputs into the batch, and its energies and overlap into the chunk's sums. Padding
// lanes repeat the last contact, and lanes this rank does not count are another rank's: both are
// kept out of the sums.
template <class Model, class Shape>
[[gnu::always_inline]] inline void Kernel<Model, Shape>::put_pack(std::size_t c, std::size_t n,
                                                                  const PackOut& o,
                                                                  EightLanes& dissipated,
                                                                  EightLanes& elastic,
                                                                  Pack& overlap) {
  const PackMask real =
      Pack([&](auto l) { return static_cast<double>(c + l); }) < static_cast<double>(n) &&
      load(b_.counted, c) > 0.5;
  dissipated.add(c, select(real, o.diss, Pack(0.0)));
  elastic.add(c, select(real, o.el, Pack(0.0)));
  overlap = vmax(overlap, o.ratio);
  store(o.fx, b_.fx, c);
  store(o.fy, b_.fy, c);
  store(o.ti, b_.t_i, c);
  store(o.tj, b_.t_j, c);
  store(o.ratio, b_.overlap, c);
  store(o.ex, b_.ex, c);
  store(o.ey, b_.ey, c);
  if constexpr (kArmsApart) {
    store(o.eti, b_.et_i, c);
    store(o.etj, b_.et_j, c);
  }
}

// B for a shape whose arms leave the normal: its narrow phase reads and advances its own history
// slots; the surface velocities are v + w x arm and the torques arm x force; the lanes whose
// bounding circles overlap while the bodies do not are zeroed (force, energies, history) and
// uncounted.
template <class Model, class Shape>
void Kernel<Model, Shape>::evaluate_pairs_apart(std::size_t n, double dt, EightLanes& dissipated,
                                                EightLanes& elastic, Pack& overlap) {
  const Pack zero(0.0);
  for (std::size_t c = 0; c < padded(n); c += kPackSize) {
    const Pack ri = load(b_.r_i, c), rj = load(b_.r_j, c);
    std::array<Pack, kShapeWidth> h_old, h_new;
    for (std::size_t s = 0; s < kShapeWidth; ++s)
      h_old[s] = load(b_.history.old[kModelWidth + s], c);
    PairInputT<Pack> in{load(b_.dx, c),   load(b_.dy, c),  load(b_.dist2, c), ri, rj,
                        load(b_.th_i, c), load(b_.th_j, c)};
    if constexpr (kSemiAxes) {
      in.ai = load(forms_[0], c);
      in.bi = load(forms_[1], c);
      in.ni = load(forms_[2], c);
      in.aj = load(forms_[3], c);
      in.bj = load(forms_[4], c);
      in.nj = load(forms_[5], c);
      in.cos_i = load(forms_[6], c);
      in.sin_i = load(forms_[7], c);
      in.cos_j = load(forms_[8], c);
      in.sin_j = load(forms_[9], c);
      in.axis_x = load(forms_[10], c);
      in.axis_y = load(forms_[11], c);
    }
    const PairContactT<Pack> g = Shape::pair(in, h_old, h_new);
    if constexpr (kSemiAxes) {
      store(g.axis_x, axis_out_[0], c);
      store(g.axis_y, axis_out_[1], c);
    }
    const PackMask touching = g.delta > zero;
    store(select(touching, load(b_.counted, c), zero), b_.counted, c);
    const Pack nx = g.nx, ny = g.ny;
    const Pack tx = -ny, ty = nx;
    KinematicsT<Pack> kin = pair_kinematics(g, load(b_.m_i, c), load(b_.m_j, c), ri, rj);
    // (v_i + w_i x a_i) - (v_j + w_j x a_j), with w x a = w (-a_y, a_x).
    const Pack wi = load(b_.w_i, c), wj = load(b_.w_j, c);
    project_velocity(kin, load(b_.vx, c) - wi * g.aiy + wj * g.ajy,
                     load(b_.vy, c) + wi * g.aix - wj * g.ajx, nx, ny);
    kin.omega_rel = load(b_.omega_rel, c);
    const ContactResponseT<Pack> out = respond(b_, c, kin, dt);
    for (std::size_t s = 0; s < kModelWidth; ++s)
      store(select(touching, load(b_.history.fresh[s], c), zero), b_.history.fresh[s], c);
    for (std::size_t s = 0; s < kShapeWidth; ++s)
      store(select(touching, h_new[s], zero), b_.history.fresh[kModelWidth + s], c);
    const ContactForceT<Pack>& cf = out.law;
    const Pack fx = select(touching, cf.f_t * tx - cf.f_n * nx, zero);
    const Pack fy = select(touching, cf.f_t * ty - cf.f_n * ny, zero);
    // On i: a_i x F; on j: a_j x (-F).
    Pack ti = g.aix * fy - g.aiy * fx, tj = g.ajy * fx - g.ajx * fy;
    Pack diss = cf.dissipated, el = cf.elastic;
    if constexpr (Model::Rolling::kActive) {
      ti += select(touching, out.rolling.torque, zero);
      tj -= select(touching, out.rolling.torque, zero);
      diss += out.rolling.dissipated;
      el += out.rolling.elastic;
    }
    Pack ratio = kin.delta / vmin(ri, rj);
    if constexpr (Model::Tracker::kExcludes) ratio = (kin.delta - out.birth_overlap) / vmin(ri, rj);
    const Pack f_el = select(touching, cf.f_el, zero);
    // The elastic normal force -f_el n on i, +f_el n on j, and its torques a x F.
    const Pack eti = -f_el * (g.aix * ny - g.aiy * nx);
    const Pack etj = f_el * (g.ajx * ny - g.ajy * nx);
    put_pack(
        c, n,
        {fx, fy, ti, tj, diss, el, select(touching, ratio, zero), -f_el * nx, -f_el * ny, eti, etj},
        dissipated, elastic, overlap);
  }
}

// C. Scatter in canonical pair order; or, with the list in storage order, the two force records
// of each contact (sum_records adds them up in canonical order).
template <class Model, class Shape>
void Kernel<Model, Shape>::scatter_pairs(ParticleStore& p, PairList& pl, std::size_t n) {
  if (!pl.canonical()) return write_records(pl, n);
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  Vec2* f_el = p.elastic_force.data();
  Field<double>* const et = kArmsApart ? p.elastic_torque() : nullptr;  // shaped stores only
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
    if constexpr (kArmsApart) {
      if (et != nullptr) {
        (*et)[i] += b_.et_i[c];
        (*et)[j] += b_.et_j[c];
      }
    }
    for (std::size_t s = 0; s < W; ++s)
      trial[static_cast<std::size_t>(k) * W + s] = b_.history.fresh[s][c];
  }
}

// The chunk's contacts whose breakage test is due, by their new histories (the values the
// commit makes the committed ones), in list order.
template <class Model, class Shape>
void Kernel<Model, Shape>::note_tests_due(std::size_t n) {
  constexpr std::size_t kTracker = Model::kLawSlots + Model::kRollingSlots;
  const double* peak = b_.history.fresh[kTracker + TrackBreakage::kPeak].data();
  const double* energy = b_.history.fresh[kTracker + TrackBreakage::kEnergy].data();
  const double* tested = b_.history.fresh[kTracker + TrackBreakage::kTested].data();
  for (std::size_t c = 0; c < n; ++c)
    if (TrackBreakage::test_due(peak[c], energy[c], tested[c])) tests_due_.push_back(b_.pair[c]);
}

template <class Model, class Shape>
void Kernel<Model, Shape>::write_records(PairList& pl, std::size_t n) {
  double* trial = new_histories(pl);
  ForceRecord* rec = records_.data();
  for (std::size_t c = 0; c < n; ++c) {
    const std::size_t k = static_cast<std::size_t>(b_.pair[c]);
    rec[2 * k] = {b_.fx[c], b_.fy[c], b_.t_i[c], b_.ex[c], b_.ey[c]};
    rec[2 * k + 1] = {-b_.fx[c], -b_.fy[c], b_.t_j[c], -b_.ex[c], -b_.ey[c]};
    if constexpr (kArmsApart) {
      elastic_torque_records_[2 * k] = b_.et_i[c];
      elastic_torque_records_[2 * k + 1] = b_.et_j[c];
    }
    for (std::size_t s = 0; s < W; ++s) trial[k * W + s] = b_.history.fresh[s][c];
  }
}

// Each owned particle's pair forces added in the order of its partners' ids, as the canonical
// scatter adds them (f - g and f + (-g) are the same number); the records of candidates not in
// contact are passed over (they hold an earlier evaluation's values).
template <class Model, class Shape>
void Kernel<Model, Shape>::sum_records(ParticleStore& p, const PairList& pl) {
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
  if constexpr (kArmsApart) {
    Field<double>* et = p.elastic_torque();  // a store with the shape fields
    for (std::size_t q = 0; et != nullptr && q < n_owned; ++q)
      for (std::int32_t s = pl.record_start[q]; s < pl.record_start[q + 1]; ++s) {
        const std::int32_t r = index[s];
        if (touch[r >> 1] != 0) (*et)[q] += elastic_torque_records_[static_cast<std::size_t>(r)];
      }
  }
}

}  // namespace dem2d::kernels
