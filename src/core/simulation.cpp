#include "core/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/contact_batch.hpp"
#include "core/contact_models.hpp"
#include "core/errors.hpp"
#include "core/fill.hpp"

namespace dem2d {

namespace {

// The pair loop, written once (style.md item 4) in the three phases of contact_batch.hpp:
// particle-particle contacts in canonical (lower id first, sorted) order, then particle-wall
// contacts. Forces and torques are accumulated into the store; energies and the drive torque
// into `tot`.
template <class Model, class Rolling>
void force_kernel(Simulation& sim, double dt, EvaluationTotals& tot) {
  ParticleStore& p = sim.particles();
  const PairTable& table = sim.pair_table();
  PairList& pl = sim.pair_list();
  ContactBatch& b = sim.contact_batch();
  const double eta_r = sim.rolling_damping();
  const Vec2* x = p.pos.data();
  const Vec2* v = p.vel.data();
  const double* w = p.omega.data();
  const double* r = p.radius.data();
  const double* m = p.mass.data();
  const std::int32_t* mat = p.material.data();
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  const std::int32_t* pi = pl.i.data();
  const std::int32_t* pj = pl.j.data();
  const ContactHistory* hist = pl.history.data();
  ContactHistory* trial = pl.trial.data();
  const int n_mat = table.n_materials();
  const std::size_t n_owned = p.n_owned();

  const PairCoeffs* coeffs = table.data();
  const bool uniform = n_mat == 1;
  const CoeffPack uniform_coeffs(coeffs[0]);
  Pack dissipated(0.0), elastic(0.0);
  const auto load = [](const Array<double>& a, std::size_t c) {
    return Pack(a.data() + c, stdx::element_aligned);
  };
  // The candidates are processed in chunks, each through phases A, B and C, so that the
  // batch arrays stay in the L1/L2 cache (one pass over a batch of every contact streamed
  // 20 arrays through memory: 1.7x slower per particle-step at 1e5 particles). Chunks run in
  // list order, so the scatter stays canonical.
  constexpr std::size_t kChunk = 512;
  const std::size_t n_pairs = pl.size();
  b.reserve(kChunk + kPackSize);
  double max_ratio = 0.0;
  std::int64_t contacts = 0;
  for (std::size_t k0 = 0; k0 < n_pairs; k0 += kChunk) {
    const std::size_t k1 = std::min(n_pairs, k0 + kChunk);
    Pack chunk_overlap(0.0);
    // A. Gather the pairs in contact; pairs apart lose their history. Branch-free compaction:
    //    every candidate is written to slot n and n advances only for a contact (whether a
    //    candidate touches is close to random, so a branch here mispredicts often).
    std::size_t n = 0;
    for (std::size_t k = k0; k < k1; ++k) {
      const std::int32_t i = pi[k], j = pj[k];
      const Vec2 d = x[j] - x[i];
      const double dist2 = norm2(d);
      const double rsum = r[i] + r[j];
      trial[k] = ContactHistory{};  // overwritten by the scatter for the pairs in contact
      b.pair[n] = static_cast<std::int32_t>(k);
      b.dx[n] = d.x;
      b.dy[n] = d.y;
      b.dist2[n] = dist2;
      // Written so that a NaN distance counts as a contact: its NaN forces are then caught by
      // check_stability instead of the particle silently dropping out of every contact.
      n += !(dist2 >= rsum * rsum) ? 1 : 0;
    }
    for (std::size_t c = 0; c < n; ++c) {
      const std::int32_t k = b.pair[c];
      const std::int32_t i = pi[k], j = pj[k];
      b.coeff[c] = mat[i] * n_mat + mat[j];
      // A pair across a rank boundary is computed on both ranks; its energies and its count
      // go to the rank that owns the lower-id particle (i) only.
      b.counted[c] = static_cast<std::size_t>(i) < n_owned ? 1.0 : 0.0;
      b.r_i[c] = r[i];
      b.r_j[c] = r[j];
      b.m_i[c] = m[i];
      b.m_j[c] = m[j];
      b.vx[c] = v[i].x - v[j].x;
      b.vy[c] = v[i].y - v[j].y;
      b.spin[c] = w[i] * r[i] + w[j] * r[j];
      b.omega_rel[c] = w[i] - w[j];
      b.xi_old[c] = hist[k].xi;
      b.mr_old[c] = hist[k].m_roll;
    }
    const std::size_t n_padded = (n + kPackSize - 1) / kPackSize * kPackSize;
    for (std::size_t c = n; c < n_padded; ++c) b.copy(c, n - 1);

    for (std::size_t c = 0; c < n_padded; c += kPackSize) {
      const Pack dist = vsqrt(load(b.dist2, c));
      const Pack inv = 1.0 / dist;
      const Pack nx = inv * load(b.dx, c), ny = inv * load(b.dy, c);
      const Pack tx = -ny, ty = nx;
      const Pack ri = load(b.r_i, c), rj = load(b.r_j, c);
      const Pack mi = load(b.m_i, c), mj = load(b.m_j, c);
      const Pack rsum = ri + rj;
      KinematicsT<Pack> kin;
      kin.delta = rsum - dist;
      kin.r_eff = ri * rj / rsum;
      kin.m_eff = mi * mj / (mi + mj);
      if constexpr (Rolling::kNeedsInertia) {
        // I + m r^2 = 7/5 m r^2 about the contact point; harmonic mean of the two bodies.
        const Pack ia = 1.4 * mi * ri * ri, ib = 1.4 * mj * rj * rj;
        kin.i_eff = ia * ib / (ia + ib);
      }
      const Pack spin = load(b.spin, c);
      const Pack vrx = load(b.vx, c) + spin * tx, vry = load(b.vy, c) + spin * ty;
      kin.v_n = vrx * nx + vry * ny;
      kin.v_t = vrx * tx + vry * ty;
      kin.omega_rel = load(b.omega_rel, c);
      const HistoryT<Pack> old{load(b.xi_old, c), load(b.mr_old, c)};
      HistoryT<Pack> h;
      const CoeffPack pc = uniform ? uniform_coeffs
                                   : CoeffPack(coeffs, [&](auto l) { return b.coeff[c + l]; });
      const ContactForceT<Pack> cf = Model::evaluate(pc, kin, old, h, dt);
      const Pack fx = cf.f_t * tx - cf.f_n * nx, fy = cf.f_t * ty - cf.f_n * ny;
      const Pack arm_i = Model::kTorqueArmIsReff ? kin.r_eff : ri;
      const Pack arm_j = Model::kTorqueArmIsReff ? kin.r_eff : rj;
      Pack ti = arm_i * cf.f_t, tj = arm_j * cf.f_t;
      Pack diss = cf.dissipated, el = cf.elastic;
      if constexpr (Rolling::kActive) {
        const RollingTorqueT<Pack> rt = Rolling::evaluate(pc, kin, cf, old, h, dt, eta_r);
        ti += rt.torque;
        tj -= rt.torque;
        diss += rt.dissipated;
        el += rt.elastic;
      }
      const Pack ratio = kin.delta / vmin(ri, rj);
      // Padding lanes repeat the last contact: keep them out of the sums.
      const PackMask real = Pack([&](auto l) { return static_cast<double>(c + l); }) < static_cast<double>(n) &&
                            load(b.counted, c) > 0.5;
      dissipated += select(real, diss, Pack(0.0));
      elastic += select(real, el, Pack(0.0));
      chunk_overlap = vmax(chunk_overlap, ratio);
      fx.copy_to(b.fx.data() + c, stdx::element_aligned);
      fy.copy_to(b.fy.data() + c, stdx::element_aligned);
      ti.copy_to(b.t_i.data() + c, stdx::element_aligned);
      tj.copy_to(b.t_j.data() + c, stdx::element_aligned);
      h.xi.copy_to(b.xi_new.data() + c, stdx::element_aligned);
      h.m_roll.copy_to(b.mr_new.data() + c, stdx::element_aligned);
      ratio.copy_to(b.overlap.data() + c, stdx::element_aligned);
    }

    // C. Scatter in canonical pair order.
    for (std::size_t c = 0; c < n; ++c) {
      const std::int32_t k = b.pair[c];
      const std::int32_t i = pi[k], j = pj[k];
      const Vec2 fi{b.fx[c], b.fy[c]};
      f[i] += fi;
      f[j] -= fi;
      tq[i] += b.t_i[c];
      tq[j] += b.t_j[c];
      trial[k] = ContactHistory{b.xi_new[c], b.mr_new[c]};
    }
    // Counted apart from the scatter: this loop vectorises, the scatter cannot.
    for (std::size_t c = 0; c < n; ++c) contacts += b.counted[c] > 0.5 ? 1 : 0;
    // The first pair at the largest overlap so far names the culprits of a blow-up.
    const double chunk_max = stdx::hmax(chunk_overlap);
    if (chunk_max > kMaxOverlapRatio && chunk_max > max_ratio) {
      for (std::size_t c = 0; c < n; ++c)
        if (b.overlap[c] == chunk_max) {
          tot.worst_a = p.id[pi[b.pair[c]]];
          tot.worst_b = p.id[pj[b.pair[c]]];
          break;
        }
    }
    max_ratio = std::max(max_ratio, chunk_max);
  }
  double dissipated_sum = stdx::reduce(dissipated), elastic_sum = stdx::reduce(elastic);

  // Walls: R* = r_i, m* = m_i; the wall's velocity at the contact point enters v_rel. The
  // same three phases as the particle pairs.
  const Walls& walls = sim.walls();
  WallPairList& wl = sim.wall_pair_list();
  WallBatch& wb = sim.wall_batch();
  const int drum = walls.drum_body();
  const Vec2 drum_center = walls.has_drum() ? walls.bodies()[drum].center : Vec2{};
  const WallElement* elements = walls.elements().data();
  const WallBody* bodies = walls.bodies().data();
  wb.reserve(wl.size() + kPackSize);
  std::size_t nw = 0;
  for (std::size_t k = 0; k < wl.size(); ++k) {
    const std::int32_t i = wl.particle[k];
    wl.trial[k] = ContactHistory{};  // overwritten by the scatter for the contacts
    // Most candidates do not touch: the cheap test skips the square root and division of the
    // full geometry (5 % of the waterfall's time, measured A/B with bench/throughput).
    if (!walls.touches(wl.element[k], x[i], r[i])) continue;
    const WallGeometry g = walls.geometry(wl.element[k], x[i], r[i]);
    if (g.delta <= 0.0) continue;  // the cheap test and the geometry may differ in the last bit
    const WallElement& e = elements[wl.element[k]];
    const Vec2 vw = walls.velocity_at(e.body, g.point);
    const Vec2 t = perp(g.n);
    const Vec2 vrel = (v[i] - vw) + (w[i] * r[i]) * t;
    wb.pair[nw] = static_cast<std::int32_t>(k);
    wb.coeff[nw] = mat[i] * n_mat + e.material;
    wb.delta[nw] = g.delta;
    wb.nx[nw] = g.n.x;
    wb.ny[nw] = g.n.y;
    wb.r[nw] = r[i];
    wb.m[nw] = m[i];
    wb.vx[nw] = vrel.x;
    wb.vy[nw] = vrel.y;
    wb.omega_rel[nw] = w[i] - bodies[e.body].omega;
    wb.xi_old[nw] = wl.history[k].xi;
    wb.mr_old[nw] = wl.history[k].m_roll;
    wb.wx[nw] = vw.x;
    wb.wy[nw] = vw.y;
    wb.px[nw] = g.point.x;
    wb.py[nw] = g.point.y;
    ++nw;
  }
  const std::size_t nw_padded = (nw + kPackSize - 1) / kPackSize * kPackSize;
  for (std::size_t c = nw; c < nw_padded; ++c) wb.copy(c, nw - 1);
  for (std::size_t c = 0; c < nw_padded; c += kPackSize) {
    const Pack nx = load(wb.nx, c), ny = load(wb.ny, c);
    const Pack tx = -ny, ty = nx;
    const Pack ri = load(wb.r, c), mi = load(wb.m, c);
    KinematicsT<Pack> kin;
    kin.delta = load(wb.delta, c);
    kin.r_eff = ri;
    kin.m_eff = mi;
    if constexpr (Rolling::kNeedsInertia) kin.i_eff = 1.4 * mi * ri * ri;
    const Pack vrx = load(wb.vx, c), vry = load(wb.vy, c);
    kin.v_n = vrx * nx + vry * ny;
    kin.v_t = vrx * tx + vry * ty;
    kin.omega_rel = load(wb.omega_rel, c);
    const HistoryT<Pack> old{load(wb.xi_old, c), load(wb.mr_old, c)};
    HistoryT<Pack> h;
    const CoeffPack pc = uniform ? uniform_coeffs
                                 : CoeffPack(coeffs, [&](auto l) { return wb.coeff[c + l]; });
    const ContactForceT<Pack> cf = Model::evaluate(pc, kin, old, h, dt);
    const Pack fx = cf.f_t * tx - cf.f_n * nx, fy = cf.f_t * ty - cf.f_n * ny;
    Pack ti = ri * cf.f_t, m_roll(0.0), diss_roll(0.0), el_roll(0.0);
    if constexpr (Rolling::kActive) {
      const RollingTorqueT<Pack> rt = Rolling::evaluate(pc, kin, cf, old, h, dt, eta_r);
      m_roll = rt.torque;
      ti += m_roll;
      diss_roll = rt.dissipated;
      el_roll = rt.elastic;
    }
    fx.copy_to(wb.fx.data() + c, stdx::element_aligned);
    fy.copy_to(wb.fy.data() + c, stdx::element_aligned);
    ti.copy_to(wb.torque.data() + c, stdx::element_aligned);
    m_roll.copy_to(wb.m_roll.data() + c, stdx::element_aligned);
    cf.dissipated.copy_to(wb.diss_law.data() + c, stdx::element_aligned);
    cf.elastic.copy_to(wb.el_law.data() + c, stdx::element_aligned);
    diss_roll.copy_to(wb.diss_roll.data() + c, stdx::element_aligned);
    el_roll.copy_to(wb.el_roll.data() + c, stdx::element_aligned);
    h.xi.copy_to(wb.xi_new.data() + c, stdx::element_aligned);
    h.m_roll.copy_to(wb.mr_new.data() + c, stdx::element_aligned);
  }
  double drum_torque = 0.0, drive_power = 0.0;
  for (std::size_t c = 0; c < nw; ++c) {
    const std::int32_t k = wb.pair[c];
    const std::int32_t i = wl.particle[k];
    const WallElement& e = elements[wl.element[k]];
    const Vec2 fi{wb.fx[c], wb.fy[c]};
    const Vec2 vw{wb.wx[c], wb.wy[c]};
    const double m_roll = wb.m_roll[c];
    f[i] += fi;
    tq[i] += wb.torque[c];
    dissipated_sum += wb.diss_law[c];
    elastic_sum += wb.el_law[c];
    if constexpr (Rolling::kActive) {
      dissipated_sum += wb.diss_roll[c];
      elastic_sum += wb.el_roll[c];
    }
    wl.trial[k] = ContactHistory{wb.xi_new[c], wb.mr_new[c]};
    // Power the wall's drive puts into the particles: F . v_wall + M Omega (the reaction couple).
    drive_power += dot(fi, vw) + m_roll * bodies[e.body].omega;
    if (e.body == drum) drum_torque += cross(Vec2{wb.px[c], wb.py[c]} - drum_center, fi) + m_roll;
    const double ratio = wb.delta[c] / wb.r[c];
    if (ratio > max_ratio) {
      max_ratio = ratio;
      tot.worst_a = p.id[i];
      tot.worst_b = -1;
    }
  }
  contacts += static_cast<std::int64_t>(nw);
  tot.contacts = contacts;
  tot.dissipated = dissipated_sum;
  tot.elastic = elastic_sum;
  tot.drum_torque = drum_torque;
  tot.drive_power = drive_power;
  tot.max_overlap = max_ratio;
}

template <class Model>
ForceKernel pick_rolling(RollingModelKind rolling) {
  switch (rolling) {
    case RollingModelKind::kNone: return &force_kernel<Model, RollingNone>;
    case RollingModelKind::kConstant: return &force_kernel<Model, RollingConstant>;
    case RollingModelKind::kEpsd: return &force_kernel<Model, RollingEpsd>;
  }
  return nullptr;
}

ForceKernel pick_kernel(const ContactSpec& c) {
  switch (c.model) {
    case ContactModelKind::kHertzMindlin: return pick_rolling<HertzMindlin>(c.rolling);
    case ContactModelKind::kThesis: return pick_rolling<ThesisModel>(c.rolling);
    case ContactModelKind::kLinear: return pick_rolling<LinearModel>(c.rolling);
  }
  return nullptr;
}

std::string format_seconds(double s) {
  std::ostringstream o;
  o.precision(3);
  o << s << " s";
  return o.str();
}

}  // namespace

double steps_per_contact_for(double restitution) {
  if (restitution >= 1.0) return 20.0;
  const double x = -std::log(restitution) / std::log(2.0);
  return std::max(20.0, 50.0 * std::pow(x, 1.77));
}

TimeScales time_scales(const Scene& scene, const ParticleStore& p) {
  TimeScales ts;
  const double g = norm(scene.run.gravity);
  // Largest expected impact speed: the drum's rim speed twice (a ball thrown off the shell
  // meets the shell coming the other way) plus free fall across the drum; without a drum,
  // the fastest initial particle plus free fall across the particles' extent.
  double v_max = 0.0, y_lo = std::numeric_limits<double>::max(), y_hi = -y_lo;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    v_max = std::max(v_max, norm(p.vel[k]) + std::abs(p.omega[k]) * p.radius[k]);
    y_lo = std::min(y_lo, p.pos[k].y - p.radius[k]);
    y_hi = std::max(y_hi, p.pos[k].y + p.radius[k]);
  }
  double fall = p.n_owned() > 0 ? y_hi - y_lo : 0.0;
  for (const WallSpec& w : scene.walls) {
    fall = std::max(fall, y_hi - std::min(w.from.y, w.to.y));
    v_max += norm(w.velocity);
  }
  if (scene.drum.present) {
    fall = 2.0 * scene.drum.radius;
    v_max = std::max(v_max, 2.0 * std::abs(scene.drum.speed) * scene.drum.radius);
  }
  ts.impact_speed = std::max(v_max + std::sqrt(2.0 * g * std::max(fall, 0.0)), 1e-3);

  ts.rayleigh = std::numeric_limits<double>::max();
  ts.hertz = std::numeric_limits<double>::max();
  const PairTable table(scene);
  // Per material: the smallest radius and mass present.
  const std::size_t nm = scene.materials.size();
  std::vector<double> r_min(nm, std::numeric_limits<double>::max());
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    r_min[p.material[k]] = std::min(r_min[p.material[k]], p.radius[k]);
  for (std::size_t a = 0; a < nm; ++a) {
    if (r_min[a] == std::numeric_limits<double>::max()) continue;
    const MaterialSpec& m = scene.materials[a];
    ts.rayleigh = std::min(ts.rayleigh, std::numbers::pi * r_min[a] * std::sqrt(m.density / m.shear_modulus) /
                                             (0.1631 * m.poisson_ratio + 0.8766));
    // Hertz contact time of the smallest sphere against a wall of the stiffest material
    // (m* = m, R* = r): t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5).
    for (std::size_t b = 0; b < nm; ++b) {
      const double mass = ParticleStore::sphere_mass(r_min[a], m.density);
      const double e_star = table(static_cast<int>(a), static_cast<int>(b)).e_star;
      const double tc = 2.868 * std::pow(mass * mass / (r_min[a] * e_star * e_star * ts.impact_speed), 0.2);
      ts.hertz = std::min(ts.hertz, tc);
    }
  }
  if (ts.rayleigh == std::numeric_limits<double>::max()) ts.rayleigh = ts.hertz = 1.0;
  // Smallest restitution among the pairs of materials present (particles and walls). The
  // thesis law's damping ratio is converted through its hertz-mindlin equivalent (T22).
  std::vector<char> used(nm, 0);
  for (std::size_t k = 0; k < p.n_owned(); ++k) used[p.material[k]] = 1;
  const Walls walls(scene);
  std::vector<char> touched(nm, 0);
  for (const WallElement& e : walls.elements()) touched[e.material] = 1;
  for (std::size_t a = 0; a < nm; ++a) {
    if (!used[a]) continue;
    for (std::size_t b = 0; b < nm; ++b) {
      if (!used[b] && !touched[b]) continue;
      const PairCoeffs& c = table(static_cast<int>(a), static_cast<int>(b));
      double e = c.restitution;
      if (scene.contact.model == ContactModelKind::kThesis)
        e = restitution_hertz_clamped(-c.zeta_n / std::sqrt(5.0 / 6.0));
      ts.restitution_min = std::min(ts.restitution_min, e);
    }
  }
  ts.steps_per_contact = steps_per_contact_for(ts.restitution_min);
  const double bound = std::min(ts.rayleigh, ts.hertz);
  ts.safe_dt = std::min(scene.run.dt_safety * ts.rayleigh, ts.hertz / ts.steps_per_contact);
  ts.limit_dt = 0.5 * bound;
  return ts;
}

Simulation::Simulation(const Scene& scene, Domain* domain)
    : scene_(scene), domain_(domain ? domain : &serial_domain_), walls_(scene_),
      pair_table_(scene_) {
  kernel_ = pick_kernel(scene_.contact);
  gravity_ = scene_.run.gravity;
  place_particles(scene_, walls_, particles_);
  scales_ = time_scales(scene_, particles_);
  if (scene_.run.dt_auto || scene_.run.dt <= 0.0) {
    dt_ = scales_.safe_dt;
  } else {
    dt_ = scene_.run.dt;
    if (dt_ > scales_.limit_dt && !scene_.run.allow_unsafe_dt) {
      std::ostringstream o;
      o << scene_.deck_path << ": error: run.dt = " << dt_ << " s is unsafe: it exceeds half of "
        << "the smallest Rayleigh time (" << format_seconds(scales_.rayleigh) << ") or Hertz contact time ("
        << format_seconds(scales_.hertz) << " at " << scales_.impact_speed << " m/s); the safe dt is "
        << scales_.safe_dt << " s (dt = \"auto\"); set run.allow_unsafe_dt = true to run anyway";
      throw InputError(o.str());
    }
  }
  double r_min = std::numeric_limits<double>::max(), r_max = 0.0;
  for (std::size_t k = 0; k < particles_.size(); ++k) {
    r_min = std::min(r_min, particles_.radius[k]);
    r_max = std::max(r_max, particles_.radius[k]);
  }
  skin_ = scene_.run.skin >= 0.0 ? scene_.run.skin : (particles_.size() ? 0.4 * r_min : 0.0);
  // Every rank placed the same particles; from here on each keeps its own (parallel runs).
  // A pair interacts within r_i + r_j + skin, so a rank needs the particles within
  // 2 r_max + skin of its region.
  halo_width_ = 2.0 * r_max + skin_;
  ghost_fields_ = {&particles_.pos, &particles_.vel, &particles_.omega};
  domain_->adopt(particles_, halo_width_);
  rebuild();
  refresh_forces();
  save_backup();
}

void Simulation::rebuild() {
  const bool parallel = domain_->size() > 1;
  if (parallel) {
    // Particles that left this rank's region move to their owner with their contact
    // histories; then a new ghost set; the lists below take their histories from the records.
    HistoryRecords records = history_records();
    domain_->migrate(particles_, records);
    domain_->exchange_halo(particles_);
    adopt_history_records(records);
  }
  ghosts_ahead_ = false;
  search_.build(particles_, walls_, skin_, pairs_, wall_pairs_);
  if (parallel) {
    // Multiples of 1/2: the sector weights built from them add exactly in any order.
    const std::size_t n_owned = particles_.n_owned();
    particle_work_.assign(n_owned, 1.0);
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
      const auto i = static_cast<std::size_t>(pairs_.i[k]), j = static_cast<std::size_t>(pairs_.j[k]);
      const bool both = i < n_owned && j < n_owned;
      if (i < n_owned) particle_work_[i] += both ? 0.5 : 1.0;
      if (j < n_owned) particle_work_[j] += both ? 0.5 : 1.0;
    }
    domain_->report_work(particle_work_);
    for (FieldBase* f : next_registry_) f->resize(n_owned);  // sized with the owned set, here
  }
  pos_at_build_.assign(particles_.pos.data(), particles_.pos.data() + particles_.n_owned());
  drum_angle_at_build_ = walls_.drum_angle();
  time_at_build_ = time_;
}

bool Simulation::rebuild_needed(double disp) const {
  // Two particles approach by at most twice the largest displacement; a wall moves at most
  // rotating_reach * |drum angle change| + translation speed * elapsed time. Decided on every
  // rank together.
  const double wall_move = walls_.rotating_reach() * std::abs(walls_.drum_angle() - drum_angle_at_build_) +
                           walls_.max_translation_speed() * (time_ - time_at_build_);
  return domain_->any(2.0 * disp + wall_move >= skin_);
}

HistoryRecords Simulation::history_records() const {
  HistoryRecords out(2);
  const auto live = [](const ContactHistory& h) { return h.xi != 0.0 || h.m_roll != 0.0; };
  for (std::size_t k = 0; k < pairs_.size(); ++k)
    if (live(pairs_.history[k])) out.push_back(pairs_.id_i[k], pairs_.id_j[k], &pairs_.history[k].xi);
  for (std::size_t k = 0; k < wall_pairs_.size(); ++k)
    if (live(wall_pairs_.history[k]))
      out.push_back(wall_pairs_.id[k], -1 - static_cast<std::int64_t>(wall_pairs_.element[k]),
                    &wall_pairs_.history[k].xi);
  return out;
}

void Simulation::adopt_history_records(const HistoryRecords& records) {
  // The lists become key + history only: NeighborSearch::build carries histories from the
  // old lists by key (pairs sorted by (id_i, id_j), walls by (id, element)).
  PairList pl;
  WallPairList wl;
  for (std::size_t r = 0; r < records.size(); ++r) {
    const ContactHistory h{records.values(r)[0], records.values(r)[1]};
    if (records.b(r) >= 0) {
      pl.id_i.push_back(records.a(r));
      pl.id_j.push_back(records.b(r));
      pl.history.push_back(h);
    } else {
      wl.id.push_back(records.a(r));
      wl.element.push_back(static_cast<std::int32_t>(-1 - records.b(r)));
      wl.history.push_back(h);
    }
  }
  // Records are sorted by (a, b); wall keys need (id, element) order: b = -1 - element runs
  // backwards within one id.
  for (std::size_t s = 0; s < wl.id.size();) {
    std::size_t e = s;
    while (e < wl.id.size() && wl.id[e] == wl.id[s]) ++e;
    std::reverse(wl.element.begin() + static_cast<std::ptrdiff_t>(s), wl.element.begin() + static_cast<std::ptrdiff_t>(e));
    std::reverse(wl.history.begin() + static_cast<std::ptrdiff_t>(s), wl.history.begin() + static_cast<std::ptrdiff_t>(e));
    s = e;
  }
  pl.i.resize(pl.id_i.size());
  pl.j.resize(pl.id_i.size());
  wl.particle.resize(wl.id.size());
  pairs_ = std::move(pl);
  wall_pairs_ = std::move(wl);
}

void Simulation::refresh_forces() {
  evaluate_forces(0.0);
  pairs_.history = pairs_.trial;
  wall_pairs_.history = wall_pairs_.trial;
}

void Simulation::evaluate_forces(double dt_history, double kick, bool owned_cleared) {
  ParticleStore& p = particles_;
  const std::size_t n = p.size();
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  for (std::size_t k = owned_cleared ? p.n_owned() : 0; k < n; ++k) {
    f[k] = {};
    tq[k] = 0.0;
  }
  totals_ = EvaluationTotals{};
  kernel_(*this, dt_history, totals_);
  // Accelerations; gravity added last, the same way for every particle. The checksum (a plain
  // sum: any NaN or infinity makes it non-finite) is tested by check_stability.
  const std::size_t n_owned = p.n_owned();
  Vec2* a = p.acc.data();
  double* al = p.alpha.data();
  const double* inv_m = p.inv_mass.data();
  const double* inv_i = p.inv_inertia.data();
  double checksum = 0.0;
  if (kick == 0.0) {
#pragma omp simd reduction(+ : checksum)
    for (std::size_t k = 0; k < n_owned; ++k) {
      a[k] = inv_m[k] * f[k] + gravity_;
      al[k] = inv_i[k] * tq[k];
      checksum += (a[k].x + a[k].y) + al[k];
    }
  } else {
    // Velocity Verlet's closing half kick, fused with the accelerations.
    Vec2* v = p.vel.data();
    double* w = p.omega.data();
    // Also the two maxima of the next step's displacement bound (check_stability).
    const Vec2* x = p.pos.data();
    const Vec2* xb = pos_at_build_.data();
    double disp2 = 0.0, speed2 = 0.0;
#pragma omp simd reduction(+ : checksum) reduction(max : disp2, speed2)
    for (std::size_t k = 0; k < n_owned; ++k) {
      a[k] = inv_m[k] * f[k] + gravity_;
      al[k] = inv_i[k] * tq[k];
      checksum += (a[k].x + a[k].y) + al[k] + (x[k].x + x[k].y);
      v[k] += kick * a[k];
      w[k] += kick * al[k];
      const double d2 = norm2(x[k] - xb[k]);
      const double s2 = norm2(v[k] + kick * a[k]);
      disp2 = disp2 > d2 ? disp2 : d2;
      speed2 = speed2 > s2 ? speed2 : s2;
    }
    next_disp2_ = disp2;
    next_speed2_ = speed2;
  }
  accel_checksum_ = checksum;
}

void Simulation::commit_history() {
  pairs_.history.swap(pairs_.trial);
  wall_pairs_.history.swap(wall_pairs_.trial);
}

void Simulation::account(const EvaluationTotals& t, double dt) {
  dissipated_ += t.dissipated;
  drive_work_ += t.drive_power * dt;
}

void Simulation::step() {
  if (scene_.run.integrator == IntegratorKind::kVerlet)
    step_verlet();
  else
    step_iterative();
  ++step_;
  check_stability();
  // The backup is taken at the same steps on every rank, and after every rebuild so that it
  // holds the particles this rank owns now (a rebuild may migrate them).
  if (step_ % 1000 == 0 || builds_at_backup_ != search_.builds()) save_backup();
}

void Simulation::run_until(double t_end) {
  while (time_ + 0.5 * dt_ < t_end) step();
}

// Velocity Verlet (kick-drift-kick); the velocity-dependent forces see the half-step velocity.
void Simulation::step_verlet() {
  ParticleStore& p = particles_;
  const std::size_t n = p.n_owned();
  const double h = 0.5 * dt_;
  Vec2* x = p.pos.data();
  Vec2* v = p.vel.data();
  const Vec2* a = p.acc.data();
  double* th = p.theta.data();
  double* w = p.omega.data();
  const double* al = p.alpha.data();
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  // Half kick, drift and clear the force accumulators in one pass. Whether the neighbour
  // lists still hold after this drift was decided at the end of the previous step
  // (check_stability), in the same reduction as the stability check.
  for (std::size_t k = 0; k < n; ++k) {
    v[k] += h * a[k];
    w[k] += h * al[k];
    x[k] += dt_ * v[k];
    th[k] += dt_ * w[k];
    f[k] = {};
    tq[k] = 0.0;
  }
  time_ = static_cast<double>(step_ + 1) * dt_;
  walls_.update(time_);
  if (rebuild_next_)
    rebuild();
  else if (!ghosts_ahead_)
    domain_->refresh_ghosts(particles_, ghost_fields_);
  ghosts_ahead_ = false;
  evaluate_forces(dt_, h, true);
  commit_history();
  account(totals_, dt_);
  last_passes_ = 1;
  passes_total_ += 1;
  passes_since_row_ += 1;
  steps_since_row_ += 1;
}

// The thesis's iterative refinement (T3-T8, T26-T33): predict the state at t + dt with the
// jerk b = (a1 - a0)/dt, re-evaluate forces there, repeat until the accelerations stop
// changing. Converged, this is Newmark's linear-acceleration method:
//   x1 = x0 + v0 dt + (2 a0 + a1) dt^2 / 6,  v1 = v0 + (a0 + a1) dt / 2.
void Simulation::step_iterative() {
  ParticleStore& p = particles_;
  const double dt = dt_, c2 = dt * dt / 6.0;
  time_ = static_cast<double>(step_ + 1) * dt_;
  walls_.update(time_);
  // The neighbour lists must hold through every pass of this step, and a rebuild (which may
  // migrate particles between ranks) cannot happen between passes: decide it now, from the
  // displacement since the last build plus a bound on this step's motion, |v| dt + |a| dt^2
  // (twice the constant-acceleration travel).
  {
    const std::size_t n = p.n_owned();
    double reach = 0.0;
    for (std::size_t k = 0; k < n; ++k)
      reach = std::max(reach, norm(p.pos[k] - pos_at_build_[k]) + norm(p.vel[k]) * dt +
                                  norm(p.acc[k]) * dt * dt);
    if (rebuild_needed(reach)) rebuild();
  }
  const std::size_t n = p.n_owned();
  x0_.assign(p.pos.data(), p.pos.data() + n);
  v0_.assign(p.vel.data(), p.vel.data() + n);
  a0_.assign(p.acc.data(), p.acc.data() + n);
  th0_.assign(p.theta.data(), p.theta.data() + n);
  w0_.assign(p.omega.data(), p.omega.data() + n);
  al0_.assign(p.alpha.data(), p.alpha.data() + n);
  a1_.assign(a0_.begin(), a0_.end());
  al1_.assign(al0_.begin(), al0_.end());
  const double eps = scene_.run.tolerance;
  const double a_ref = std::max(norm(gravity_), 1e-12);

  auto predict = [&]() {
    Vec2* x = p.pos.data();
    Vec2* v = p.vel.data();
    double* th = p.theta.data();
    double* w = p.omega.data();
    for (std::size_t k = 0; k < n; ++k) {
      x[k] = x0_[k] + dt * v0_[k] + c2 * (2.0 * a0_[k] + a1_[k]);
      v[k] = v0_[k] + (0.5 * dt) * (a0_[k] + a1_[k]);
      th[k] = th0_[k] + dt * w0_[k] + c2 * (2.0 * al0_[k] + al1_[k]);
      w[k] = w0_[k] + (0.5 * dt) * (al0_[k] + al1_[k]);
    }
  };

  int pass = 0;
  bool converged = false;
  const int max_passes = std::max(1, scene_.run.max_passes);
  while (pass < max_passes && !converged) {
    predict();
    domain_->refresh_ghosts(particles_, ghost_fields_);
    evaluate_forces(dt);
    ++pass;
    // Converged when |a^k - a^(k-1)| <= eps (|a^k| + a_ref) for every DOF (T31) on every
    // rank; angular accelerations are compared in units of a_ref / r.
    bool ok = true;
    for (std::size_t k = 0; k < n && ok; ++k) {
      const Vec2 a = p.acc[k];
      const double scale_w = 1.0 / p.radius[k];
      ok = std::abs(a.x - a1_[k].x) <= eps * (std::abs(a.x) + a_ref) &&
           std::abs(a.y - a1_[k].y) <= eps * (std::abs(a.y) + a_ref) &&
           std::abs(p.alpha[k] - al1_[k]) <= eps * (std::abs(p.alpha[k]) + a_ref * scale_w);
    }
    ok = !domain_->any(!ok);
    for (std::size_t k = 0; k < n; ++k) {
      a1_[k] = p.acc[k];
      al1_[k] = p.alpha[k];
    }
    converged = ok && pass > 1;
  }
  // Final state from the last accelerations (p.acc already holds a1 for the next step).
  predict();
  if (!converged) ++unconverged_steps_;
  commit_history();
  account(totals_, dt);
  last_passes_ = pass;
  passes_total_ += pass;
  passes_since_row_ += pass;
  steps_since_row_ += 1;
}

void Simulation::check_stability() {
  // One reduction per step in the common case; the details only when some rank is in trouble.
  // The same reduction carries Verlet's rebuild decision for the next step: the next drift
  // moves a particle by dt |v + a dt/2| (known now), so the displacement bound since the last
  // build is sqrt(max |x - x_build|^2) + dt sqrt(max |v + a dt/2|^2), and the walls move by at
  // most their speed times dt more.
  const bool local_ok = std::isfinite(accel_checksum_) && totals_.max_overlap <= kMaxOverlapRatio;
  double reduce[2] = {local_ok ? 0.0 : 1.0, std::sqrt(next_disp2_) + dt_ * std::sqrt(next_speed2_)};
  if (scene_.run.integrator == IntegratorKind::kVerlet && domain_->size() > 1) {
    // The same round hands the ghosts the state their owners drift them to next (the drift of
    // step_verlet, operation for operation, so the bits agree), and the next step skips the
    // refresh. Wasted when the next step rebuilds (one step in a hundred or more).
    const std::span<const std::int32_t> sources = domain_->halo_sources();
    const double h = 0.5 * dt_;
    const Vec2* x = particles_.pos.data();
    const Vec2* v = particles_.vel.data();
    const Vec2* a = particles_.acc.data();
    const double* w = particles_.omega.data();
    const double* al = particles_.alpha.data();
    for (const std::int32_t k : sources) {
      const Vec2 v_next = v[k] + h * a[k];
      next_vel_[k] = v_next;
      next_pos_[k] = x[k] + dt_ * v_next;
      next_omega_[k] = w[k] + h * al[k];
    }
    domain_->exchange_step(particles_, next_registry_, ghost_fields_, reduce);
    ghosts_ahead_ = true;
  } else {
    domain_->max(reduce);
  }
  if (!std::isfinite(reduce[1])) reduce[0] = 1.0;
  const double wall_move = walls_.rotating_reach() * (std::abs(walls_.drum_angle() - drum_angle_at_build_) +
                                                      std::abs(walls_.drum_speed()) * dt_) +
                           walls_.max_translation_speed() * (time_ + dt_ - time_at_build_);
  rebuild_next_ = 2.0 * reduce[1] + wall_move >= skin_;
  if (reduce[0] == 0.0) return;
  const double max_overlap = domain_->max(totals_.max_overlap);
  const bool finite = !domain_->any(!std::isfinite(accel_checksum_));
  std::ostringstream o;
  o << "the run became unstable at step " << step_ << " (t = " << time_ << " s): ";
  if (!finite) {
    o << "non-finite positions or accelerations";
    // interface.md (exit 3) asks for the particle ids: name this rank's first few.
    int named = 0;
    for (std::size_t k = 0; k < particles_.n_owned() && named < 5; ++k) {
      const Vec2 a = particles_.acc[k];
      if (std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(particles_.alpha[k]) &&
          std::isfinite(particles_.pos[k].x) && std::isfinite(particles_.pos[k].y))
        continue;
      o << (named++ ? ", particle " : " of particle ") << particles_.id[k];
    }
  } else {
    // The pair at the largest overlap, named alike on every rank (ids are below 2^53).
    const bool mine = totals_.max_overlap == max_overlap;
    const auto worst_a = static_cast<std::int64_t>(domain_->max(mine ? static_cast<double>(totals_.worst_a) : -2.0));
    const auto worst_b = static_cast<std::int64_t>(domain_->max(mine ? static_cast<double>(totals_.worst_b) : -2.0));
    o << "overlap " << max_overlap << " of a radius between particle " << worst_a;
    if (worst_b >= 0)
      o << " and particle " << worst_b;
    else
      o << " and a wall";
  }
  o << "; dt = " << dt_ << " s, the safe dt is " << scales_.safe_dt << " s";
  const std::int64_t failed_step = step_;
  const double failed_time = time_;
  if (!finite) {
    restore_backup();
    o << "; the last snapshot holds the last finite state (t = " << time_ << " s)";
  }
  throw UnstableError(o.str(), failed_step, failed_time);
}

void Simulation::save_backup() {
  const std::size_t n = particles_.n_owned();
  backup_pos_.assign(particles_.pos.data(), particles_.pos.data() + n);
  backup_vel_.assign(particles_.vel.data(), particles_.vel.data() + n);
  backup_theta_.assign(particles_.theta.data(), particles_.theta.data() + n);
  backup_omega_.assign(particles_.omega.data(), particles_.omega.data() + n);
  backup_id_.assign(particles_.id.data(), particles_.id.data() + n);
  backup_time_ = time_;
  backup_step_ = step_;
  builds_at_backup_ = search_.builds();
}

void Simulation::restore_backup() {
  const std::size_t n = particles_.n_owned();
  if (backup_pos_.size() != n || !std::equal(backup_id_.begin(), backup_id_.end(), particles_.id.data()))
    return;
  std::copy(backup_pos_.begin(), backup_pos_.end(), particles_.pos.data());
  std::copy(backup_vel_.begin(), backup_vel_.end(), particles_.vel.data());
  std::copy(backup_theta_.begin(), backup_theta_.end(), particles_.theta.data());
  std::copy(backup_omega_.begin(), backup_omega_.end(), particles_.omega.data());
  time_ = backup_time_;
  step_ = backup_step_;
}

SeriesRow Simulation::diagnostics() const {
  const ParticleStore& p = particles_;
  SeriesRow row;
  row.time = time_;
  row.step = step_;
  double ke = 0.0, re = 0.0, pe = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    ke += 0.5 * p.mass[k] * norm2(p.vel[k]);
    re += 0.5 * p.mass[k] * 0.4 * p.radius[k] * p.radius[k] * p.omega[k] * p.omega[k];
    pe -= p.mass[k] * dot(gravity_, p.pos[k]);
  }
  row.particles = domain_->sum(static_cast<std::int64_t>(p.n_owned()));
  row.contacts = domain_->sum(totals_.contacts);
  row.kinetic_energy = domain_->sum(ke);
  row.rotational_energy = domain_->sum(re);
  row.potential_energy = domain_->sum(pe);
  row.elastic_energy = domain_->sum(totals_.elastic);
  row.dissipated_energy = domain_->sum(dissipated_);
  row.drum_torque = domain_->sum(totals_.drum_torque);
  row.drum_power = row.drum_torque * walls_.drum_omega();
  row.drive_work = domain_->sum(drive_work_);
  row.passes = steps_since_row_ > 0 ? static_cast<double>(passes_since_row_) / steps_since_row_
                                    : static_cast<double>(last_passes_);
  return row;
}

void Simulation::reset_pass_window() {
  passes_since_row_ = 0;
  steps_since_row_ = 0;
}

}  // namespace dem2d
