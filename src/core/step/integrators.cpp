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
// The scheme of the run

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
  ClosingKick closing = ahead_ ? closing_kick_drift(p, x_build, dt_, gravity_, s.drift_mirror())
                               : closing_kick(p, x_build, dt_, gravity_);
  // The closing kick booked the late work of the whole torque; a superellipse's elastic normal
  // force has a torque too, whose work is the elastic energy's (not dissipated): taken back.
  if (const Field<double>* et = p.elastic_torque()) {
    double late = 0.0;
    for (std::size_t k = 0; k < p.n_owned(); ++k) late += (*et)[k] * (0.5 * dt_ * p.alpha[k]);
    closing.late_loss += dt_ * late;
  }
  s.commit(dt_, closing.late_loss);
  passes_.add(1);
  return end_of_step_round(s, closing, s.totals().max_overlap);
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
    if (!next_theta_ && s.ghost_fields().size() > next_registry_.size()) {
      next_theta_ = std::make_unique<Field<double>>("next_angle", next_registry_);
      next_theta_->resize(next_pos_.size());
    }
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
      if (next_theta_) (*next_theta_)[k] = p.theta[k];
      continue;
    }
    const Drifted d = kick_drift(p.pos[k], p.vel[k], p.acc[k], p.omega[k], p.alpha[k], h, dt_);
    next_pos_[k] = d.x;
    next_vel_[k] = d.v;
    next_omega_[k] = d.w;
    if (next_theta_) (*next_theta_)[k] = p.theta[k] + dt_ * d.w;  // as kick_drift_owned
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
