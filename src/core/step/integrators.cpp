#include "core/step/integrators.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dem2d {

// ---------------------------------------------------------------------------------------------
// Rebuild decision

void RebuildMonitor::record(const ParticleStore& p, const Walls& walls, double time) {
  pos_at_build_.assign(p.pos.data(), p.pos.data() + p.n_owned());
  walls_at_build_ = walls.pose(time);
}

bool RebuildMonitor::due(double displacement, const Walls& walls, double time, double ahead) const {
  return 2.0 * displacement + walls.moved_since(walls_at_build_, time, ahead) >= skin_;
}

// ---------------------------------------------------------------------------------------------
// Shared pieces

std::unique_ptr<Integrator> make_integrator(const RunSpec& run, double dt, Vec2 gravity) {
  if (run.integrator == IntegratorKind::kIterative)
    return std::make_unique<IterativeIntegrator>(dt, gravity, run.tolerance,
                                                 std::max(1, run.max_passes));
  return std::make_unique<VelocityVerlet>(dt, gravity);
}

double accelerations(ParticleStore& p, Vec2 gravity) {
  const std::size_t n = p.n_owned();
  Vec2* a = p.acc.data();
  double* al = p.alpha.data();
  const Vec2* f = p.force.data();
  const double* tq = p.torque.data();
  const double* inv_m = p.inv_mass.data();
  const double* inv_i = p.inv_inertia.data();
  double checksum = 0.0;
#pragma omp simd reduction(+ : checksum)
  for (std::size_t k = 0; k < n; ++k) {
    accelerate(a[k], al[k], f[k], tq[k], inv_m[k], inv_i[k], gravity);
    checksum += (a[k].x + a[k].y) + al[k];
  }
  return checksum;
}

// ---------------------------------------------------------------------------------------------
// Velocity Verlet

StepOutcome VelocityVerlet::step(StepStages& s) {
  open_step(s);
  s.advance_clock();
  const bool rebuilt = lists_or_ghosts(s);
  s.contact_forces(dt_, /*owned_cleared=*/true);
  return close_step(s, rebuilt);
}

// v += a dt/2, x += v dt, accumulators cleared: done by the last step's closing pass when it ran
// ahead. The owned elastic forces are zero from the last closing kick on, but not after the
// set-up's or a population change's evaluation.
void VelocityVerlet::open_step(StepStages& s) {
  ParticleStore& p = s.particles();
  if (!elastic_cleared_) {
    std::fill(p.elastic_force.data(), p.elastic_force.data() + p.n_owned(), Vec2{});
    elastic_cleared_ = true;
  }
  if (!ahead_) kick_drift_owned(p, dt_, s.drift_mirror());
  ahead_ = false;
}

// New neighbour lists when the last step's round decided so (true), else the ghosts' state from
// their owners, unless that round already handed it over.
bool VelocityVerlet::lists_or_ghosts(StepStages& s) {
  const bool rebuild = rebuild_next_;
  if (rebuild)
    s.rebuild();
  else if (!ghosts_ahead_)
    s.refresh_ghosts();
  ghosts_ahead_ = false;
  return rebuild;
}

// v += a dt/2, and when allowed the next step's kick-drift in the same pass (not after a rebuild:
// the simulation keeps a backup of the state then; nor before a population change); the commit
// and the step's round.
StepOutcome VelocityVerlet::close_step(StepStages& s, bool rebuilt) {
  ParticleStore& p = s.particles();
  const bool population_changes = s.population_changes();
  const Vec2* x_build = s.rebuilds().positions_at_build();
  ahead_ = run_ahead_allowed_ && !rebuilt && !population_changes;
  const ClosingKick closing = ahead_
                                  ? closing_kick_drift(p, x_build, dt_, gravity_, s.drift_mirror())
                                  : closing_kick(p, x_build, dt_, gravity_);
  s.commit(dt_, closing.late_loss);
  passes_.add(1);
  return end_of_step_round(s, closing, s.totals().max_overlap);
}

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

// The drift taken back (a failed step's report): x - dt v, v - a dt/2, w - alpha dt/2,
// theta - dt w, which gives the step's end state to the last bits, not exactly. The forces of
// the step are not restored (cleared for the next step).
void VelocityVerlet::step_back(ParticleStore& p) {
  if (!ahead_) return;
  const double h = 0.5 * dt_;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    p.theta[k] -= dt_ * p.omega[k];
    p.pos[k] -= dt_ * p.vel[k];
    p.vel[k] -= h * p.acc[k];
    p.omega[k] -= h * p.alpha[k];
  }
  ahead_ = false;
}

// The step's one collective: stability, and whether the next step rebuilds. The next drift
// moves a particle by dt |v + a dt/2| (known now), so the displacement since the last build is
// at most sqrt(max |x - x_build|^2) + dt sqrt(max |v + a dt/2|^2), and the walls move by at most
// their speed times dt more. In parallel the same round hands the ghosts the state their owners
// drift them to next, and the next step skips the refresh (wasted when it rebuilds, one step in
// a hundred or more).
StepOutcome VelocityVerlet::end_of_step_round(StepStages& s, const ClosingKick& c,
                                              double max_overlap) {
  const double motion = dt_ * std::sqrt(c.motion2);
  const bool local_ok =
      std::isfinite(c.checksum) && max_overlap <= kMaxOverlapRatio && motion <= kMaxStepMotion;
  double reduce[2] = {local_ok ? 0.0 : 1.0, std::sqrt(c.disp2) + dt_ * std::sqrt(c.speed2)};
  Domain& domain = s.domain();
  if (domain.size() > 1) {
    prepare_ghosts_ahead(s.particles(), domain.halo_sources());
    domain.exchange_step(s.particles(), next_registry_, s.ghost_fields(), reduce);
    ghosts_ahead_ = true;
  } else {
    domain.max(reduce);
  }
  if (!std::isfinite(reduce[1])) reduce[0] = 1.0;
  rebuild_next_ = s.rebuilds().due(reduce[1], s.walls(), s.time(), dt_);
  StepOutcome out{reduce[0] != 0.0, c.checksum, motion};
  if (out.unstable && motion > kMaxStepMotion) {  // name the particle (rare: only now)
    const ParticleStore& p = s.particles();
    for (std::size_t k = 0; k < p.n_owned() && out.motion_id < 0; ++k) {
      // The coming drift's velocity: in the store already when the step ran ahead.
      const Vec2 v_half = ahead_ ? p.vel[k] : p.vel[k] + (0.5 * dt_) * p.acc[k];
      if (dt_ * norm(v_half) / p.radius[k] > kMaxStepMotion) out.motion_id = p.id[k];
    }
  }
  return out;
}

void VelocityVerlet::prepare_ghosts_ahead(const ParticleStore& p,
                                          std::span<const std::int32_t> sources) {
  const double h = 0.5 * dt_;
  for (const std::int32_t k : sources) {
    if (ahead_) {  // the closing kick drifted them already
      next_pos_[k] = p.pos[k];
      next_vel_[k] = p.vel[k];
      next_omega_[k] = p.omega[k];
      continue;
    }
    const Drifted d = kick_drift(p.pos[k], p.vel[k], p.acc[k], p.omega[k], p.alpha[k], h, dt_);
    next_pos_[k] = d.x;
    next_vel_[k] = d.v;
    next_omega_[k] = d.w;
  }
}

// The next-state fields are sized with the owned set; the new ghosts hold the current state,
// not the drifted one.
void VelocityVerlet::after_rebuild(std::size_t n_owned) {
  for (FieldBase* f : next_registry_) f->resize(n_owned);
  ghosts_ahead_ = false;
}

// ---------------------------------------------------------------------------------------------
// The thesis's iterative scheme

StepOutcome IterativeIntegrator::step(StepStages& s) {
  ParticleStore& p = s.particles();
  s.advance_clock();
  if (rebuild_due(s)) s.rebuild();
  save_start(p);
  int pass = 0;
  bool converged = false;
  double checksum = 0.0;
  StepOutcome passes;
  while (pass < max_passes_ && !converged) {
    predict(p);
    s.refresh_ghosts();
    s.contact_forces(dt_, /*owned_cleared=*/false);
    checksum = accelerations(p, gravity_);
    ++pass;
    passes.shift_first = passes.shift_last;
    double largest[2] = {largest_change(p, passes.shift_mine, passes.shift_id), 0.0};
    largest[1] = passes.shift_mine;
    s.domain().max(largest);  // one collective per pass: the change and the shift, every rank
    passes.shift_last = largest[1];
    converged = pass > 1 && largest[0] <= tolerance_;
  }
  // Not settled: passes that cycle mildly (an epsd branch, a friction direction or a contact
  // that flips between passes) leave end positions that differ by a tiny fraction of a radius,
  // and the step is taken (counted). When one of the last two passes moved a particle's end
  // position by more than kMaxUnsettledShift of its radius, no pass is a usable answer (a stiff
  // contact on in one pass and off in the next, or passes that grow: dt too large for the fixed
  // point, omega_contact dt > sqrt(6)), and the step is an error.
  passes.diverged = !converged && pass >= 2 &&
                    std::max(passes.shift_first, passes.shift_last) > kMaxUnsettledShift;
  const double booked_power = loss_power(p);
  predict(p);  // the final state from the last accelerations (p.acc holds a1 for the next step)
  if (!converged) ++passes_.unconverged_steps;
  s.commit(dt_, late_loss(p, booked_power));
  passes_.add(pass);
  return end_of_step_round(s, checksum, passes);
}

// The step's verdict on every rank. The state returned is checked, not only the last pass: a
// step whose passes did not settle may end far from where its forces were evaluated (bodies
// through each other).
StepOutcome IterativeIntegrator::end_of_step_round(StepStages& s, double checksum,
                                                   StepOutcome out) const {
  out.checksum = checksum;
  largest_motion(s.particles(), out);
  const bool local_ok = std::isfinite(checksum) && s.totals().max_overlap <= kMaxOverlapRatio &&
                        out.motion <= kMaxStepMotion;
  out.unstable = s.domain().any(!local_ok) || out.diverged;
  return out;
}

// The largest |x1 - x0| / r of the step just taken (a NaN position gives NaN: not <= the bound).
void IterativeIntegrator::largest_motion(const ParticleStore& p, StepOutcome& out) const {
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const double m = norm(p.pos[k] - x0_[k]) / p.radius[k];
    if (!(m <= out.motion)) {
      out.motion = m;
      out.motion_id = p.id[k];
    }
  }
}

// The neighbour lists must hold through every pass of this step, and a rebuild (which may
// migrate particles between ranks) cannot happen between passes: decide it now, from the
// displacement since the last build plus a bound on this step's motion, |v| dt + |a| dt^2
// (twice the constant-acceleration travel).
bool IterativeIntegrator::rebuild_due(StepStages& s) const {
  const ParticleStore& p = s.particles();
  const Vec2* x_build = s.rebuilds().positions_at_build();
  double reach = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    reach = std::max(
        reach, norm(p.pos[k] - x_build[k]) + norm(p.vel[k]) * dt_ + norm(p.acc[k]) * dt_ * dt_);
  return s.domain().any(s.rebuilds().due(reach, s.walls(), s.time(), 0.0));
}

// sum G . v + M w over the owned particles, G the contact force less its elastic normal part,
// M the torque: the power of the forces whose work the contact laws book as dissipated.
double IterativeIntegrator::loss_power(const ParticleStore& p) const {
  double sum = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    sum += dot(p.force[k] - p.elastic_force[k], p.vel[k]) + p.torque[k] * p.omega[k];
  return sum;
}

// The energy ledger's completion. The laws booked the work of the loss forces G1 of this step's
// last pass as -dt G1 . v with the velocities of that pass (`booked_power`). The scheme's
// velocity update v1 = v0 + dt (a0 + a1) / 2 changes the kinetic energy by exactly
// dt (F0 + F1) / 2 . (v0 + v1) / 2: each step's forces work over two steps, half in each. The
// exact loss of this step is then -dt/4 (G0 + G1) . (v0 + v1), G0 the previous step's loss forces;
// the difference is returned.
double IterativeIntegrator::late_loss(const ParticleStore& p, double booked_power) const {
  double exact = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    exact += dot(g0_[k] + (p.force[k] - p.elastic_force[k]), v0_[k] + p.vel[k]) +
             (m0_[k] + p.torque[k]) * (w0_[k] + p.omega[k]);
  return dt_ * booked_power - 0.25 * dt_ * exact;
}

void IterativeIntegrator::save_start(const ParticleStore& p) {
  const std::size_t n = p.n_owned();
  // The loss forces of the previous step's last pass (they migrated with their particles).
  g0_.resize(n);
  for (std::size_t k = 0; k < n; ++k) g0_[k] = p.force[k] - p.elastic_force[k];
  m0_.assign(p.torque.data(), p.torque.data() + n);
  x0_.assign(p.pos.data(), p.pos.data() + n);
  v0_.assign(p.vel.data(), p.vel.data() + n);
  a0_.assign(p.acc.data(), p.acc.data() + n);
  th0_.assign(p.theta.data(), p.theta.data() + n);
  w0_.assign(p.omega.data(), p.omega.data() + n);
  al0_.assign(p.alpha.data(), p.alpha.data() + n);
  a1_.assign(a0_.begin(), a0_.end());
  al1_.assign(al0_.begin(), al0_.end());
}

void IterativeIntegrator::predict(ParticleStore& p) const {
  const double dt = dt_, c2 = dt * dt / 6.0;
  Vec2* x = p.pos.data();
  Vec2* v = p.vel.data();
  double* th = p.theta.data();
  double* w = p.omega.data();
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    x[k] = x0_[k] + dt * v0_[k] + c2 * (2.0 * a0_[k] + a1_[k]);
    v[k] = v0_[k] + (0.5 * dt) * (a0_[k] + a1_[k]);
    th[k] = th0_[k] + dt * w0_[k] + c2 * (2.0 * al0_[k] + al1_[k]);
    w[k] = w0_[k] + (0.5 * dt) * (al0_[k] + al1_[k]);
  }
}

// This rank's largest relative change of the accelerations since the last pass,
// max |a^k - a^(k-1)| / (|a^k| + a_ref) over every DOF, angular accelerations in units of
// a_ref / r (converged when it is at most the tolerance on every rank, T31), and its particle
// (`id`). The latest accelerations become a1.
double IterativeIntegrator::largest_change(const ParticleStore& p, double& shift,
                                           std::int64_t& shift_id) {
  const double a_ref = std::max(norm(gravity_), 1e-12);
  const double c2 = dt_ * dt_ / 6.0;  // x1 moves by dt^2 / 6 times a change of a1
  const std::size_t n = p.n_owned();
  double worst = 0.0;
  shift = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 a = p.acc[k];
    const double r = p.radius[k], ref_w = a_ref / r;
    const Vec2 da = a - a1_[k];
    const double dal = p.alpha[k] - al1_[k];
    const double c = std::max({std::abs(da.x) / (std::abs(a.x) + a_ref),
                               std::abs(da.y) / (std::abs(a.y) + a_ref),
                               std::abs(dal) / (std::abs(p.alpha[k]) + ref_w)});
    worst = std::isnan(c) || c > worst ? c : worst;  // a NaN change stays the largest
    const double moved = c2 * std::max(norm(da), std::abs(dal) * r) / r;
    if (std::isnan(moved) || moved > shift) {
      shift = moved;
      shift_id = p.id[k];
    }
    a1_[k] = a;
    al1_[k] = p.alpha[k];
  }
  return worst;
}

}  // namespace dem2d
