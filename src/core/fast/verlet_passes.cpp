#include "core/fast/verlet_passes.hpp"

#include <algorithm>

namespace dem2d {

namespace {

// The opening half kick and drift of particle k (kick_drift) and what it writes: x, v, w,
// theta += dt w, force and torque cleared, and with `mirror` its line. kick_drift_owned's loop
// and closing_kick_drift's both use it.
[[gnu::always_inline]] inline void drift_one(std::size_t k, double h, double dt, Vec2* x, Vec2* v,
                                             const Vec2* a, double* th, double* w, const double* al,
                                             Vec2* f, double* tq, [[maybe_unused]] const double* r,
                                             [[maybe_unused]] const double* m,
                                             [[maybe_unused]] const std::int32_t* mat,
                                             [[maybe_unused]] PairKinematics* mirror) {
  const Drifted d = kick_drift(x[k], v[k], a[k], w[k], al[k], h, dt);
  x[k] = d.x;
  v[k] = d.v;
  w[k] = d.w;
  th[k] += dt * d.w;
  f[k] = {};
  tq[k] = 0.0;
#if DEM2D_VECTOR_GATHER
  if (mirror) store_kinematics(mirror[k], x[k], v[k], d.w, r[k], m[k], mat[k]);
#endif
}

#if DEM2D_VECTOR_GATHER
// What the drift of particles k..k+3 writes once their new state is in registers (x, v and w
// of the four side by side): drift_one's stores, four at a time. drift_fours and close_four
// both use it.
[[gnu::always_inline]] inline void store_drift4(std::size_t k, double dt, __m512d x_new,
                                                __m512d v_half, __m256d w_new, Vec2* x, Vec2* v,
                                                double* th, double* w, Vec2* f, double* tq,
                                                const double* r, const double* m,
                                                const std::int32_t* mat, PairKinematics* mirror) {
  _mm512_storeu_pd(&x[k].x, x_new);
  _mm512_storeu_pd(&v[k].x, v_half);
  _mm256_storeu_pd(w + k, w_new);
  _mm256_storeu_pd(
      th + k, _mm256_add_pd(_mm256_loadu_pd(th + k), _mm256_mul_pd(_mm256_set1_pd(dt), w_new)));
  _mm512_storeu_pd(&f[k].x, _mm512_setzero_pd());
  _mm256_storeu_pd(tq + k, _mm256_setzero_pd());
  if (mirror) store_kinematics4(mirror + k, x_new, v_half, w_new, r + k, m + k, mat + k);
}

// Particles [0, 4 floor(n / 4)) of drift_particles, four at a time: the same multiplications and
// additions in the same order (no FMA contraction), so the same bits; returns where it stopped.
// The scalar loop took 37 instructions per particle (9 % of the dense block's time).
template <bool kMirror>
std::size_t drift_fours(std::size_t n, double h, double dt, Vec2* x, Vec2* v, const Vec2* a,
                        double* th, double* w, const double* al, Vec2* f, double* tq,
                        [[maybe_unused]] const double* r, [[maybe_unused]] const double* m,
                        [[maybe_unused]] const std::int32_t* mat,
                        [[maybe_unused]] PairKinematics* mirror) {
  const __m512d h8 = _mm512_set1_pd(h), dt8 = _mm512_set1_pd(dt);
  const __m256d h4 = _mm256_set1_pd(h);
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    // Vec2 columns: (x, y) of four particles in one register.
    const __m512d v_half =
        _mm512_add_pd(_mm512_loadu_pd(&v[k].x), _mm512_mul_pd(h8, _mm512_loadu_pd(&a[k].x)));
    const __m512d x_new = _mm512_add_pd(_mm512_loadu_pd(&x[k].x), _mm512_mul_pd(dt8, v_half));
    const __m256d w_new =
        _mm256_add_pd(_mm256_loadu_pd(w + k), _mm256_mul_pd(h4, _mm256_loadu_pd(al + k)));
    store_drift4(k, dt, x_new, v_half, w_new, x, v, th, w, f, tq, r, m, mat,
                 kMirror ? mirror : nullptr);
  }
  return k;
}
#endif

// The opening half kick and drift of particles [0, n), and with kMirror their pair-gather mirror
// lines, read back from the store just written (pointers as arguments: captured by a lambda they
// ran out of registers); with `fours`, drift_fours takes the whole fours.
template <bool kMirror>
void drift_particles(std::size_t n, double h, double dt, Vec2* x, Vec2* v, const Vec2* a,
                     double* th, double* w, const double* al, Vec2* f, double* tq,
                     [[maybe_unused]] const double* r, [[maybe_unused]] const double* m,
                     [[maybe_unused]] const std::int32_t* mat,
                     [[maybe_unused]] PairKinematics* mirror, [[maybe_unused]] bool fours) {
  std::size_t from = 0;
#if DEM2D_VECTOR_GATHER
  if (fours) from = drift_fours<kMirror>(n, h, dt, x, v, a, th, w, al, f, tq, r, m, mat, mirror);
#endif
  for (std::size_t k = from; k < n; ++k)
    drift_one(k, h, dt, x, v, a, th, w, al, f, tq, r, m, mat, kMirror ? mirror : nullptr);
}

}  // namespace

// The drift also writes the pair gather's mirror lines when the contact loop keeps them
// (`mirror`, core/fast/kinematics_mirror.hpp): a second pass over the store would re-read it.
void kick_drift_owned(ParticleStore& p, double dt, PairKinematics* mirror, bool four_at_a_time) {
  const auto drift = mirror ? drift_particles<true> : drift_particles<false>;
  drift(p.n_owned(), 0.5 * dt, dt, p.pos.data(), p.vel.data(), p.acc.data(), p.theta.data(),
        p.omega.data(), p.alpha.data(), p.force.data(), p.torque.data(), p.radius.data(),
        p.mass.data(), p.material.data(), mirror, four_at_a_time);
}

// The closing half kick (closing_kick, closing_kick_drift).
// The energy ledger's completion: Verlet applies the force F of step n+1 over the closing half
// kick and the next opening one, so its work on the kinetic energy is exactly F . v(n+1) dt, with
// v(n+1) the velocity after this kick. The contact laws booked their losses with the half-step
// velocity they see; the rest, -dt sum (G . dv + M dw) over the particles, is `late_loss`, with
// G the contact force less its elastic normal part, M the torque, dv = a dt/2 and dw = alpha dt/2
// this kick's change (the pair sums cancel into the particle sums: the force on j is minus that
// on i).
// Without it the ledger drifted at first order in dt (0.33 % of the drive work over 10 s of the
// waterfall at 1e-5 s).
namespace {

constexpr std::size_t kSumLanes = 8;

// The closing sums in their fixed order (ClosingKick): particle k of the first whole eights into
// lane k mod 8, the rest into lane 0.
struct ClosingSums {
  double checksum[kSumLanes] = {};
  double late_power[kSumLanes] = {};
  double disp2 = 0.0, speed2 = 0.0, motion2 = 0.0;
  ClosingKick result(double dt) const {
    ClosingKick c{0.0, disp2, speed2, motion2, 0.0};
    double late = 0.0;
    for (std::size_t l = 0; l < kSumLanes; ++l) {
      c.checksum += checksum[l];
      late += late_power[l];
    }
    c.late_loss = -dt * late;
    return c;
  }
};

// The columns the closing kick (and the drift) read and write; `mirror` may be null.
struct ClosingColumns {
  Vec2 *a, *v, *x, *f, *f_el;
  double *al, *w, *th, *tq;
  const double *inv_m, *inv_i, *r, *m;
  const std::int32_t* mat;
  const Vec2* x_build;
  PairKinematics* mirror;
};

ClosingColumns closing_columns(ParticleStore& p, const Vec2* x_build, PairKinematics* mirror) {
  return {p.acc.data(),
          p.vel.data(),
          p.pos.data(),
          p.force.data(),
          p.elastic_force.data(),
          p.alpha.data(),
          p.omega.data(),
          p.theta.data(),
          p.torque.data(),
          p.inv_mass.data(),
          p.inv_inertia.data(),
          p.radius.data(),
          p.mass.data(),
          p.material.data(),
          x_build,
          mirror};
}

// The running maximum: `most` unless `next` is larger (or `most` is NaN; not std::max, which
// keeps `most` then). Scalar here, four lanes below.
[[gnu::always_inline]] inline double keep_larger(double most, double next) {
  return most > next ? most : next;
}

// The closing half kick of particle k, its share of the sums in `lane`.
[[gnu::always_inline]] inline void close_one(std::size_t k, std::size_t lane, double h, Vec2 g,
                                             const ClosingColumns& c, ClosingSums& sums) {
  accelerate(c.a[k], c.al[k], c.f[k], c.tq[k], c.inv_m[k], c.inv_i[k], g);
  sums.checksum[lane] += (c.a[k].x + c.a[k].y) + c.al[k] + (c.x[k].x + c.x[k].y);
  c.v[k] += h * c.a[k];
  c.w[k] += h * c.al[k];
  sums.late_power[lane] += dot(c.f[k] - c.f_el[k], h * c.a[k]) + c.tq[k] * (h * c.al[k]);
  c.f_el[k] = {};  // cleared here, where it is read, rather than with the force in kick_drift
  const double d2 = norm2(c.x[k] - c.x_build[k]);
  const double s2 = norm2(c.v[k] + h * c.a[k]);
  const double m2 = s2 / (c.r[k] * c.r[k]);
  sums.disp2 = keep_larger(sums.disp2, d2);
  sums.speed2 = keep_larger(sums.speed2, s2);
  sums.motion2 = keep_larger(sums.motion2, m2);
}

std::size_t sum_lane(std::size_t k, std::size_t whole) { return k < whole ? k % kSumLanes : 0; }

#if DEM2D_VECTOR_GATHER
// Four particles' (x, y) pairs -> x + y of each, in four lanes.
[[gnu::always_inline]] inline __m256d pair_sums(__m512d u) {
  const __m512i evens = _mm512_setr_epi64(0, 2, 4, 6, 0, 2, 4, 6);
  return _mm512_castpd512_pd256(
      _mm512_permutexvar_pd(evens, _mm512_add_pd(u, _mm512_permute_pd(u, 0x55))));
}
// Four per-particle values, each twice (beside a Vec2 column).
[[gnu::always_inline]] inline __m512d twice(const double* q) {
  const __m512i pairs = _mm512_setr_epi64(0, 0, 1, 1, 2, 2, 3, 3);
  return _mm512_permutexvar_pd(pairs, _mm512_zextpd256_pd512(_mm256_loadu_pd(q)));
}
// keep_larger, four lanes at once.
[[gnu::always_inline]] inline __m256d keep_larger(__m256d most, __m256d next) {
  return _mm256_blendv_pd(next, most, _mm256_cmp_pd(most, next, _CMP_GT_OQ));
}

struct FourMaxima {
  __m256d disp2 = _mm256_setzero_pd(), speed2 = _mm256_setzero_pd(), motion2 = _mm256_setzero_pd();
};

// close_one (and with kDrift drift_one) of particles k..k+3: the same operations in the same
// order (no FMA); their shares of the sums into `checksum` and `late` (their lanes).
template <bool kDrift>
[[gnu::always_inline]] inline void close_four(std::size_t k, double h, double dt, Vec2 g,
                                              const ClosingColumns& c, FourMaxima& most,
                                              __m256d& checksum, __m256d& late) {
  const __m512d F = _mm512_loadu_pd(&c.f[k].x);
  const __m256d T = _mm256_loadu_pd(c.tq + k);
  const __m512d A = _mm512_add_pd(_mm512_mul_pd(twice(c.inv_m + k), F),
                                  _mm512_setr_pd(g.x, g.y, g.x, g.y, g.x, g.y, g.x, g.y));
  const __m256d AL = _mm256_mul_pd(_mm256_loadu_pd(c.inv_i + k), T);
  const __m512d X = _mm512_loadu_pd(&c.x[k].x);
  checksum = _mm256_add_pd(checksum, _mm256_add_pd(_mm256_add_pd(pair_sums(A), AL), pair_sums(X)));
  const __m512d hA = _mm512_mul_pd(_mm512_set1_pd(h), A);
  const __m256d hAL = _mm256_mul_pd(_mm256_set1_pd(h), AL);
  const __m512d V = _mm512_add_pd(_mm512_loadu_pd(&c.v[k].x), hA);
  const __m256d W = _mm256_add_pd(_mm256_loadu_pd(c.w + k), hAL);
  const __m512d G = _mm512_sub_pd(F, _mm512_loadu_pd(&c.f_el[k].x));
  late = _mm256_add_pd(late, _mm256_add_pd(pair_sums(_mm512_mul_pd(G, hA)), _mm256_mul_pd(T, hAL)));
  const __m512d D = _mm512_sub_pd(X, _mm512_loadu_pd(&c.x_build[k].x));
  // The next step's opening half kick: v + a dt/2 (also the speed of the round's bound).
  const __m512d V_half = _mm512_add_pd(V, hA);
  const __m256d s2 = pair_sums(_mm512_mul_pd(V_half, V_half));
  const __m256d rk = _mm256_loadu_pd(c.r + k);
  most.disp2 = keep_larger(most.disp2, pair_sums(_mm512_mul_pd(D, D)));
  most.speed2 = keep_larger(most.speed2, s2);
  most.motion2 = keep_larger(most.motion2, _mm256_div_pd(s2, _mm256_mul_pd(rk, rk)));
  _mm512_storeu_pd(&c.a[k].x, A);
  _mm256_storeu_pd(c.al + k, AL);
  _mm512_storeu_pd(&c.f_el[k].x, _mm512_setzero_pd());
  if constexpr (!kDrift) {
    _mm512_storeu_pd(&c.v[k].x, V);
    _mm256_storeu_pd(c.w + k, W);
    return;
  }
  const __m512d X_new = _mm512_add_pd(X, _mm512_mul_pd(_mm512_set1_pd(dt), V_half));
  store_drift4(k, dt, X_new, V_half, _mm256_add_pd(W, hAL), c.x, c.v, c.th, c.w, c.f, c.tq, c.r,
               c.m, c.mat, c.mirror);
}

#endif

#if DEM2D_VECTOR_GATHER
// The four-lane registers of the whole eights into the sums (before the first particle past
// them): lanes 0-3 and 4-7 of the two sums, the maxima lane by lane.
void flush_lanes(const FourMaxima& most, const __m256d (&checksum)[2], const __m256d (&late)[2],
                 ClosingSums& sums) {
  for (std::size_t half = 0; half < 2; ++half) {
    _mm256_storeu_pd(sums.checksum + 4 * half, checksum[half]);
    _mm256_storeu_pd(sums.late_power + 4 * half, late[half]);
  }
  alignas(32) double lanes[3][4];
  _mm256_store_pd(lanes[0], most.disp2);
  _mm256_store_pd(lanes[1], most.speed2);
  _mm256_store_pd(lanes[2], most.motion2);
  for (std::size_t l = 0; l < 4; ++l) {
    sums.disp2 = keep_larger(sums.disp2, lanes[0][l]);
    sums.speed2 = keep_larger(sums.speed2, lanes[1][l]);
    sums.motion2 = keep_larger(sums.motion2, lanes[2][l]);
  }
}
#endif

// closing_kick (kDrift false) and closing_kick_drift (true): the closing pass over the owned
// particles. With `four_at_a_time` (AVX-512), eight particles per iteration over the first whole
// eights, the sums' lanes 0-3 and 4-7 in two registers each; then the rest one at a time into
// lane 0 (ClosingSums' order either way).
template <bool kDrift>
ClosingKick close(ParticleStore& p, const Vec2* x_build, double dt, Vec2 gravity,
                  PairKinematics* mirror, [[maybe_unused]] bool four_at_a_time) {
  const ClosingColumns c = closing_columns(p, x_build, mirror);
  const double h = 0.5 * dt;
  const std::size_t n = p.n_owned(), whole = n / kSumLanes * kSumLanes;
  ClosingSums sums;
  std::size_t k = 0;
#if DEM2D_VECTOR_GATHER
  if (four_at_a_time) {
    FourMaxima most;
    __m256d checksum[2] = {_mm256_setzero_pd(), _mm256_setzero_pd()};
    __m256d late[2] = {_mm256_setzero_pd(), _mm256_setzero_pd()};
    for (; k < whole; k += 8) {
      close_four<kDrift>(k, h, dt, gravity, c, most, checksum[0], late[0]);
      close_four<kDrift>(k + 4, h, dt, gravity, c, most, checksum[1], late[1]);
    }
    flush_lanes(most, checksum, late, sums);
  }
#endif
  for (; k < n; ++k) {
    close_one(k, sum_lane(k, whole), h, gravity, c, sums);
    if constexpr (kDrift)
      drift_one(k, h, dt, c.x, c.v, c.a, c.th, c.w, c.al, c.f, c.tq, c.r, c.m, c.mat, c.mirror);
  }
  return sums.result(dt);
}

}  // namespace

ClosingKick closing_kick(ParticleStore& p, const Vec2* x_build, double dt, Vec2 gravity,
                         bool four_at_a_time) {
  return close<false>(p, x_build, dt, gravity, nullptr, four_at_a_time);
}

ClosingKick closing_kick_drift(ParticleStore& p, const Vec2* x_build, double dt, Vec2 gravity,
                               PairKinematics* mirror, bool four_at_a_time) {
  return close<true>(p, x_build, dt, gravity, mirror, four_at_a_time);
}

}  // namespace dem2d
