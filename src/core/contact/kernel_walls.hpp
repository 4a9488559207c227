// The particle-wall contacts of the force kernel (Kernel<Model, Shape>, contact_kernel.hpp): the
// disc against each listed element, the model on packs, then forces, energies, histories and one
// load record per contact (core/geometry/wall_loads.hpp), in the wall list's order.
#pragma once

#include <array>
#include <vector>

#include "core/contact/contact_kernel.hpp"
#include "core/geometry/wall_loads.hpp"

namespace dem2d::kernels {

// Walls: R* = r_i, m* = m_i; the wall's velocity at the contact point enters v_rel. The same
// three phases as the particle pairs, in one batch.
template <class Model, class Shape>
void Kernel<Model, Shape>::wall_contacts(ParticleStore& p, const Walls& walls, WallPairList& wl,
                                         double dt, EvaluationTotals& tot,
                                         std::vector<WallLoad>& loads) {
  wb_.reserve(wl.size() + kPackSize);
  const std::size_t n = gather_walls(p, walls, wl);
  evaluate_walls(n, dt);
  loads.clear();
  loads.reserve(n);
  scatter_walls(p, wl, n, tot, loads);
  if constexpr (kTrackRelease)
    next_live_walls_.insert(next_live_walls_.end(), wb_.pair.data(), wb_.pair.data() + n);
  tot.contacts += static_cast<std::int64_t>(n);
}

template <class Model, class Shape>
std::size_t Kernel<Model, Shape>::gather_walls(const ParticleStore& p, const Walls& walls,
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
    if constexpr (kArmsApart) {
      // The shape's own geometry, arm and history (written here: the model's slots come in B).
      std::array<double, kShapeWidth> h_old, h_new;
      for (std::size_t s = 0; s < kShapeWidth; ++s) h_old[s] = old[k * W + kModelWidth + s];
      WallContact wc;
      if constexpr (kSemiAxes)
        wc = Shape::wall(walls, wl.element[k], x[i], r[i], p.theta[i], form_of(p, i), h_old, h_new);
      else
        wc = Shape::wall(walls, wl.element[k], x[i], r[i], p.theta[i], h_old, h_new);
      if (!(wc.g.delta > 0.0)) continue;
      const Vec2 vw = walls.velocity_at(e.body, wc.g.point);
      for (std::size_t s = 0; s < kShapeWidth; ++s)
        wb_.history.fresh[kModelWidth + s][n] = h_new[s];
      wb_.ax[n] = wc.arm.x;
      wb_.ay[n] = wc.arm.y;
      wb_.r_eff[n] = wc.r_eff;
      n = put_wall(n, k, i, mat[i] * n_mat_ + e.material, wc.g, (v[i] - vw) + w[i] * perp(wc.arm),
                   vw, w[i] - bodies[e.body].omega, p, old);
      continue;
    }
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
    n = put_wall(n, k, i, mat[i] * n_mat_ + e.material, g, vrel, vw, w[i] - bodies[e.body].omega, p,
                 old);
  }
  for (std::size_t c = n; c < padded(n); ++c) wb_.copy(c, n - 1);
  return n;
}

// Wall entry k, particle i, in contact: its inputs into slot n of the batch; returns n + 1.
template <class Model, class Shape>
[[gnu::always_inline]] inline std::size_t Kernel<Model, Shape>::put_wall(
    std::size_t n, std::size_t k, std::int32_t i, std::int32_t coeff, const WallGeometry& g,
    Vec2 vrel, Vec2 vw, double omega_rel, const ParticleStore& p, const double* old) {
  wb_.pair[n] = static_cast<std::int32_t>(k);
  wb_.coeff[n] = coeff;
  wb_.delta[n] = g.delta;
  wb_.nx[n] = g.n.x;
  wb_.ny[n] = g.n.y;
  wb_.r[n] = p.radius[i];
  wb_.m[n] = p.mass[i];
  wb_.vx[n] = vrel.x;
  wb_.vy[n] = vrel.y;
  wb_.omega_rel[n] = omega_rel;
  for (std::size_t s = 0; s < W; ++s) wb_.history.old[s][n] = old[k * W + s];
  wb_.wx[n] = vw.x;
  wb_.wy[n] = vw.y;
  wb_.px[n] = g.point.x;
  wb_.py[n] = g.point.y;
  return n + 1;
}

template <class Model, class Shape>
void Kernel<Model, Shape>::evaluate_walls(std::size_t n, double dt) {
  for (std::size_t c = 0; c < padded(n); c += kPackSize) {
    const Pack nx = load(wb_.nx, c), ny = load(wb_.ny, c);
    const Pack tx = -ny, ty = nx;
    const Pack ri = load(wb_.r, c), mi = load(wb_.m, c);
    KinematicsT<Pack> kin;
    kin.delta = load(wb_.delta, c);
    kin.r_eff = kArmsApart ? load(wb_.r_eff, c) : ri;
    kin.m_eff = mi;
    if constexpr (Model::Rolling::kNeedsInertia) kin.i_eff = Shape::contact_inertia(mi, ri);
    project_velocity(kin, load(wb_.vx, c), load(wb_.vy, c), nx, ny);
    kin.omega_rel = load(wb_.omega_rel, c);
    const ContactResponseT<Pack> out = respond(wb_, c, kin, dt);
    const ContactForceT<Pack>& cf = out.law;
    const Pack fx = cf.f_t * tx - cf.f_n * nx, fy = cf.f_t * ty - cf.f_n * ny;
    // arm x force: r f_t for a disc.
    Pack ti = kArmsApart ? load(wb_.ax, c) * fy - load(wb_.ay, c) * fx : ri * cf.f_t;
    if constexpr (Model::Rolling::kActive) ti += out.rolling.torque;
    store(fx, wb_.fx, c);
    store(fy, wb_.fy, c);
    store(ti, wb_.torque, c);
    if constexpr (kArmsApart)  // the elastic normal force -f_el n's torque
      store(-cf.f_el * (load(wb_.ax, c) * ny - load(wb_.ay, c) * nx), wb_.et, c);
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

template <class Model, class Shape>
void Kernel<Model, Shape>::scatter_walls(ParticleStore& p, WallPairList& wl, std::size_t n,
                                         EvaluationTotals& tot, std::vector<WallLoad>& loads) {
  Vec2* f = p.force.data();
  double* tq = p.torque.data();
  Vec2* f_el = p.elastic_force.data();
  Field<double>* const et = kArmsApart ? p.elastic_torque() : nullptr;  // shaped stores only
  double dissipated = tot.dissipated, elastic = tot.elastic, max_ratio = tot.max_overlap;
  for (std::size_t c = 0; c < n; ++c) {
    const std::int32_t k = wb_.pair[c];
    const std::int32_t i = wl.particle[k];
    const Vec2 fi{wb_.fx[c], wb_.fy[c]};
    const double m_roll = wb_.m_roll[c];
    f[i] += fi;
    tq[i] += wb_.torque[c];
    f_el[i] += Vec2{wb_.ex[c], wb_.ey[c]};
    if constexpr (kArmsApart)
      if (et != nullptr) (*et)[i] += wb_.et[c];
    dissipated += wb_.diss_law[c];
    elastic += wb_.el_law[c];
    if constexpr (Model::Rolling::kActive) {
      dissipated += wb_.diss_roll[c];
      elastic += wb_.el_roll[c];
    }
    for (std::size_t s = 0; s < W; ++s)
      wl.trial[static_cast<std::size_t>(k) * W + s] = wb_.history.fresh[s][c];
    loads.push_back(
        {wl.element[k], i, Vec2{wb_.px[c], wb_.py[c]}, fi, m_roll, Vec2{wb_.wx[c], wb_.wy[c]}});
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

}  // namespace dem2d::kernels
