// Phase A of the pair loop (contact_batch.hpp) up to the contact model: which candidates touch,
// and the particle data of those that do, copied into the batch columns. Two implementations,
// the same IEEE operations in the same order (so the same bits):
//   - one candidate at a time (any CPU);
//   - with AVX-512, eight candidates at a time from a one-line-per-particle mirror of the store
//     (PairKinematics), the candidates in contact packed by compress (register form: the memory
//     form is microcoded on AMD).
// The block scene spent 36 % of its time in the scalar form (perf, 2026-11-26); the columns
// feed phase B's packs either way.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <limits>

#include "core/base/vec2.hpp"
#include "core/fast/kinematics_mirror.hpp"
#include "core/fast/simd.hpp"

namespace dem2d::kernels {

inline constexpr bool kHaveVectorGather = DEM2D_VECTOR_GATHER != 0;

// What phase A reads, and the batch columns it writes: contact c of the batch is list entry
// pair[c], of particles bi[c] and bj[c]. The columns hold at least (k1 - k0) + 8 entries: the
// vector form stores whole packs past the last contact.
struct GatherColumns {
  const Vec2* x;
  const Vec2* v;
  const double* w;
  const double* r;
  const double* m;
  const std::int32_t* material;
  const std::int32_t* li;  // the list's particles
  const std::int32_t* lj;
  std::size_t entries;    // the list's length
  const double* history;  // the list's committed history, `width` values per entry
  std::size_t width;
  std::size_t n_owned;
  std::int32_t n_mat;  // 1: no material index is written
  std::int32_t* pair;
  std::int32_t* bi;
  std::int32_t* bj;
  std::int32_t* coeff;
  double* counted;
  double* dx;  // x_j - x_i
  double* dy;
  double* dist2;
  double* r_i;
  double* r_j;
  double* m_i;
  double* m_j;
  double* vx;
  double* vy;
  double* spin;
  double* omega_rel;
  double* const* old;  // `width` columns
  // For a shape whose arms leave the normal (gather_frames_scalar), else null: the angles, and
  // each body's spin and angle in the batch.
  const double* theta = nullptr;
  double* w_i = nullptr;
  double* w_j = nullptr;
  double* th_i = nullptr;
  double* th_j = nullptr;
  // For a shape with semi-axes (kShapeHasSemiAxes), else null: the store's a, b, n, and each
  // body's in the batch.
  const double* semi_a = nullptr;
  const double* semi_b = nullptr;
  const double* exponent = nullptr;
  double* a_i = nullptr;
  double* b_i = nullptr;
  double* n_i = nullptr;
  double* a_j = nullptr;
  double* b_j = nullptr;
  double* n_j = nullptr;
};

// The candidates [k0, k1) in contact, packed into the columns from 0 on; returns their count.
// Branch-free compaction: every candidate is written to slot n and n advances only for a
// contact (whether a candidate touches is close to random, so a branch mispredicts often).
// Written so that a NaN distance counts as a contact: its NaN forces are then caught by the
// stability check instead of the particle silently dropping out of every contact.
inline std::size_t find_contacts_scalar(const GatherColumns& o, std::size_t k0, std::size_t k1) {
  std::size_t n = 0;
  for (std::size_t k = k0; k < k1; ++k) {
    const std::int32_t i = o.li[k], j = o.lj[k];
    const Vec2 d = o.x[j] - o.x[i];
    const double dist2 = norm2(d);
    const double rsum = o.r[i] + o.r[j];
    o.pair[n] = static_cast<std::int32_t>(k);
    o.bi[n] = i;
    o.bj[n] = j;
    o.dx[n] = d.x;
    o.dy[n] = d.y;
    o.dist2[n] = dist2;
    n += !(dist2 >= rsum * rsum) ? 1 : 0;
  }
  return n;
}

// Contacts [c0, c1) of the batch (padding lanes included: they name the last contact).
inline void gather_inputs_scalar(const GatherColumns& o, std::size_t c0, std::size_t c1) {
  for (std::size_t c = c0; c < c1; ++c) {
    const std::int32_t i = o.bi[c], j = o.bj[c];
    const std::size_t k = static_cast<std::size_t>(o.pair[c]);
    // One material: the kernel uses its one coefficient set and reads no index.
    if (o.n_mat != 1) o.coeff[c] = o.material[i] * o.n_mat + o.material[j];
    // A pair across a rank boundary is computed on both ranks; its energies and its count go
    // to the rank that owns the lower-id particle (i) only.
    o.counted[c] = static_cast<std::size_t>(i) < o.n_owned ? 1.0 : 0.0;
    o.r_i[c] = o.r[i];
    o.r_j[c] = o.r[j];
    o.m_i[c] = o.m[i];
    o.m_j[c] = o.m[j];
    o.vx[c] = o.v[i].x - o.v[j].x;
    o.vy[c] = o.v[i].y - o.v[j].y;
    o.spin[c] = o.w[i] * o.r[i] + o.w[j] * o.r[j];
    o.omega_rel[c] = o.w[i] - o.w[j];
    for (std::size_t s = 0; s < o.width; ++s) o.old[s][c] = o.history[k * o.width + s];
  }
}

// Each body's spin and angle of contacts [c0, c1), for a shape whose arms leave the normal.
inline void gather_frames_scalar(const GatherColumns& o, std::size_t c0, std::size_t c1) {
  for (std::size_t c = c0; c < c1; ++c) {
    const std::int32_t i = o.bi[c], j = o.bj[c];
    o.w_i[c] = o.w[i];
    o.w_j[c] = o.w[j];
    o.th_i[c] = o.theta[i];
    o.th_j[c] = o.theta[j];
  }
  if (o.semi_a == nullptr) return;
  for (std::size_t c = c0; c < c1; ++c) {
    const std::int32_t i = o.bi[c], j = o.bj[c];
    o.a_i[c] = o.semi_a[i];
    o.b_i[c] = o.semi_b[i];
    o.n_i[c] = o.exponent[i];
    o.a_j[c] = o.semi_a[j];
    o.b_j[c] = o.semi_b[j];
    o.n_j[c] = o.exponent[j];
  }
}

#if DEM2D_VECTOR_GATHER

// The mirror's lines [from, n) from the store (core/fast/kinematics_mirror.hpp).
inline void fill_kinematics(PairKinematics* out, const Vec2* x, const Vec2* v, const double* w,
                            const double* r, const double* m, const std::int32_t* material,
                            std::size_t from, std::size_t n) {
  for (std::size_t i = from; i < n; ++i)
    store_kinematics(out[i], x[i], v[i], w[i], r[i], m[i], material[i]);
}

// Eight rows of eight doubles to eight columns (a[f] lane l = row l's field f).
[[gnu::always_inline]] inline void transpose8(__m512d (&a)[8]) {
  const __m512d t0 = _mm512_unpacklo_pd(a[0], a[1]), t1 = _mm512_unpackhi_pd(a[0], a[1]);
  const __m512d t2 = _mm512_unpacklo_pd(a[2], a[3]), t3 = _mm512_unpackhi_pd(a[2], a[3]);
  const __m512d t4 = _mm512_unpacklo_pd(a[4], a[5]), t5 = _mm512_unpackhi_pd(a[4], a[5]);
  const __m512d t6 = _mm512_unpacklo_pd(a[6], a[7]), t7 = _mm512_unpackhi_pd(a[6], a[7]);
  const __m512i even = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
  const __m512i odd = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  // Rows 0-3 and 4-7: fields 0|4, 2|6, 1|5, 3|7.
  const __m512d s0 = _mm512_permutex2var_pd(t0, even, t2), s1 = _mm512_permutex2var_pd(t0, odd, t2);
  const __m512d s2 = _mm512_permutex2var_pd(t1, even, t3), s3 = _mm512_permutex2var_pd(t1, odd, t3);
  const __m512d s4 = _mm512_permutex2var_pd(t4, even, t6), s5 = _mm512_permutex2var_pd(t4, odd, t6);
  const __m512d s6 = _mm512_permutex2var_pd(t5, even, t7), s7 = _mm512_permutex2var_pd(t5, odd, t7);
  const __m512i low = _mm512_setr_epi64(0, 1, 2, 3, 8, 9, 10, 11);
  const __m512i high = _mm512_setr_epi64(4, 5, 6, 7, 12, 13, 14, 15);
  a[0] = _mm512_permutex2var_pd(s0, low, s4);
  a[4] = _mm512_permutex2var_pd(s0, high, s4);
  a[2] = _mm512_permutex2var_pd(s1, low, s5);
  a[6] = _mm512_permutex2var_pd(s1, high, s5);
  a[1] = _mm512_permutex2var_pd(s2, low, s6);
  a[5] = _mm512_permutex2var_pd(s2, high, s6);
  a[3] = _mm512_permutex2var_pd(s3, low, s7);
  a[7] = _mm512_permutex2var_pd(s3, high, s7);
}

[[gnu::always_inline]] inline void compress_store(double* to, __mmask8 keep, __m512d v) {
  _mm512_storeu_pd(to, _mm512_maskz_compress_pd(keep, v));
}
[[gnu::always_inline]] inline void compress_store(std::int32_t* to, __mmask8 keep, __m256i v) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(to), _mm256_maskz_compress_epi32(keep, v));
}

// Where slot s of lane l lies among the history values of eight consecutive list entries (W
// each): value l W + s, in register (l W + s) / 8. For the register pair (q, q + 1): each lane's
// index into the pair (permutex2var), and the lanes whose value lies in it.
struct HistoryPick {
  alignas(64) std::int64_t at[8];
  unsigned lanes;
};
template <std::size_t W>
constexpr std::array<HistoryPick, W*((W + 1) / 2)> history_picks() {
  std::array<HistoryPick, W*((W + 1) / 2)> out{};
  for (std::size_t s = 0; s < W; ++s)
    for (std::size_t q = 0; q < W; q += 2) {
      HistoryPick& p = out[s * ((W + 1) / 2) + q / 2];
      for (std::size_t l = 0; l < 8; ++l) {
        const std::size_t f = l * W + s;
        p.at[l] = 0;
        if (f / 8 == q || f / 8 == q + 1) {
          p.at[l] = static_cast<std::int64_t>(f - 8 * q);
          p.lanes |= 1u << l;
        }
      }
    }
  return out;
}

// The history of eight consecutive list entries (8 W contiguous doubles at `h`) as W columns.
template <std::size_t W>
[[gnu::always_inline]] inline void history_columns(const double* h, std::size_t count,
                                                   __m512d (&out)[W]) {
  static constexpr std::array<HistoryPick, W*((W + 1) / 2)> kPicks = history_picks<W>();
  __m512d reg[W + 1];
  if (count == 8) {
    for (std::size_t q = 0; q < W; ++q) reg[q] = _mm512_loadu_pd(h + 8 * q);
  } else {  // the list ends within the pack: read no further
    const auto valid = static_cast<std::ptrdiff_t>(count * W);
    for (std::size_t q = 0; q < W; ++q) {
      const std::ptrdiff_t left = valid - static_cast<std::ptrdiff_t>(8 * q);
      const unsigned n = left <= 0 ? 0u : left >= 8 ? 8u : static_cast<unsigned>(left);
      reg[q] = _mm512_maskz_loadu_pd(static_cast<__mmask8>((1u << n) - 1u), h + 8 * q);
    }
  }
  reg[W] = _mm512_setzero_pd();
  for (std::size_t s = 0; s < W; ++s) {
    out[s] = _mm512_setzero_pd();
    for (std::size_t q = 0; q < W; q += 2) {
      const HistoryPick& p = kPicks[s * ((W + 1) / 2) + q / 2];
      const __m512d both = _mm512_permutex2var_pd(reg[q], _mm512_load_si512(p.at), reg[q + 1]);
      out[s] = _mm512_mask_mov_pd(out[s], static_cast<__mmask8>(p.lanes), both);
    }
  }
}

// Both steps of the scalar forms at once, eight candidates at a time: the candidates [k0, k1) in
// contact and their inputs, packed into the columns from 0 on; returns their count. W: the
// history width.
inline constexpr std::size_t kPrefetch = 64;

template <std::size_t W>
inline std::size_t gather_contacts_vector(const PairKinematics* kin, const GatherColumns& cols,
                                          std::size_t k0, std::size_t k1) {
  const GatherColumns o = cols;  // a local copy: the int stores below cannot alias it
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i n_owned = _mm256_set1_epi32(static_cast<std::int32_t>(o.n_owned));
  const __m512d n_mat = _mm512_set1_pd(static_cast<double>(o.n_mat));
  std::size_t n = 0;
  for (std::size_t k = k0; k < k1; k += 8) {
    // The last, partial pack repeats its last candidate (masked out of the contacts).
    const std::size_t count = std::min<std::size_t>(8, k1 - k);
    alignas(32) std::int32_t tail_i[8], tail_j[8];
    const std::int32_t* pi = o.li + k;
    const std::int32_t* pj = o.lj + k;
    if (count < 8) {
      for (std::size_t l = 0; l < 8; ++l) {
        tail_i[l] = pi[std::min(l, count - 1)];
        tail_j[l] = pj[std::min(l, count - 1)];
      }
      pi = tail_i;
      pj = tail_j;
    }
    const __mmask8 live = static_cast<__mmask8>((1u << count) - 1u);
    // The partners' lines kPrefetch candidates ahead (the lower-id particles come in order and
    // the hardware finds them): 0.75 of the run time of the 1e5 drum, whose mirror is past L2.
    if (k + kPrefetch + 8 <= o.entries)
      for (std::size_t l = 0; l < 8; ++l)
        _mm_prefetch(reinterpret_cast<const char*>(&kin[o.lj[k + kPrefetch + l]]), _MM_HINT_T0);
    __m512d a[8], b[8];
    for (std::size_t l = 0; l < 8; ++l) {
      a[l] = _mm512_load_pd(&kin[pi[l]].x);
      b[l] = _mm512_load_pd(&kin[pj[l]].x);
    }
    transpose8(a);
    transpose8(b);
    const __m512d dx = _mm512_sub_pd(b[0], a[0]), dy = _mm512_sub_pd(b[1], a[1]);
    const __m512d dist2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
    const __m512d rsum = _mm512_add_pd(a[5], b[5]);
    // Not greater or equal, unordered true: !(dist2 >= rsum * rsum) of the scalar form.
    const __mmask8 touch =
        _mm512_mask_cmp_pd_mask(live, dist2, _mm512_mul_pd(rsum, rsum), _CMP_NGE_UQ);
    if (touch == 0) continue;
    const __m256i vi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pi));
    const __m256i vj = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pj));
    compress_store(o.pair + n, touch,
                   _mm256_add_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(k)), lane));
    compress_store(o.bi + n, touch, vi);
    compress_store(o.bj + n, touch, vj);
    if (o.n_mat != 1)  // small integers: exact in doubles
      compress_store(o.coeff + n, touch,
                     _mm512_cvttpd_epi32(_mm512_add_pd(_mm512_mul_pd(a[7], n_mat), b[7])));
    const __mmask8 owned = _mm256_cmplt_epu32_mask(vi, n_owned);
    compress_store(o.counted + n, touch,
                   _mm512_mask_blend_pd(owned, _mm512_setzero_pd(), _mm512_set1_pd(1.0)));
    compress_store(o.dx + n, touch, dx);
    compress_store(o.dy + n, touch, dy);
    compress_store(o.dist2 + n, touch, dist2);
    compress_store(o.r_i + n, touch, a[5]);
    compress_store(o.r_j + n, touch, b[5]);
    compress_store(o.m_i + n, touch, a[6]);
    compress_store(o.m_j + n, touch, b[6]);
    compress_store(o.vx + n, touch, _mm512_sub_pd(a[2], b[2]));
    compress_store(o.vy + n, touch, _mm512_sub_pd(a[3], b[3]));
    compress_store(o.spin + n, touch,
                   _mm512_add_pd(_mm512_mul_pd(a[4], a[5]), _mm512_mul_pd(b[4], b[5])));
    compress_store(o.omega_rel + n, touch, _mm512_sub_pd(a[4], b[4]));
    if constexpr (W > 0) {
      __m512d history[W];
      history_columns<W>(o.history + k * W, count, history);
      for (std::size_t s = 0; s < W; ++s) compress_store(o.old[s] + n, touch, history[s]);
    }
    n += static_cast<std::size_t>(std::popcount(static_cast<unsigned>(touch)));
  }
  return n;
}

#endif  // DEM2D_VECTOR_GATHER

}  // namespace dem2d::kernels
