// The energy that contacts ending in a step release (Kernel<Model, Shape>, contact_kernel.hpp):
// what their springs held at the end of the last step, booked as dissipated (linear law only: a
// Hertz spring holds nothing at zero overlap).
#pragma once

#include <array>
#include <vector>

#include "core/contact/contact_kernel.hpp"

namespace dem2d::kernels {

// A contact that ended in this step releases the energy its springs held at the end of the last
// step, at the overlap then: booked as dissipated (docs/output.md). Rare: out of line.
template <class Model, class Shape>
[[gnu::noinline]] void Kernel<Model, Shape>::release_pair(const ParticleStore& p, std::int32_t i,
                                                          std::int32_t j, double dt,
                                                          const double* h) {
  if (static_cast<std::size_t>(i) >= p.n_owned()) return;  // booked where i is owned
  // x_j - x_i a step ago: before the drift dt v (Verlet: exactly the drift just taken).
  const Vec2 d_old = (p.pos[j] - p.pos[i]) - dt * (p.vel[j] - p.vel[i]);
  const double ri = p.radius[i], rj = p.radius[j];
  const auto& c = coeffs_[p.material[i] * n_mat_ + p.material[j]];
  if constexpr (kArmsApart) {
    // The shape's geometry a step ago (angles before the drift dt w), its history as committed.
    std::array<double, kShapeWidth> h_old, h_new;
    for (std::size_t s = 0; s < kShapeWidth; ++s) h_old[s] = h[kModelWidth + s];
    PairInputT<double> in{d_old.x,
                          d_old.y,
                          norm2(d_old),
                          ri,
                          rj,
                          p.theta[i] - dt * p.omega[i],
                          p.theta[j] - dt * p.omega[j]};
    if constexpr (kSemiAxes) {
      const SuperEllipse si = form_of(p, i), sj = form_of(p, j);
      in.ai = si.a, in.bi = si.b, in.ni = si.n, in.aj = sj.a, in.bj = sj.b, in.nj = sj.n;
    }
    const PairContactT<double> g = Shape::pair(in, h_old, h_new);
    released_ += Model::spring_energy(c, g.r_eff, g.delta, h);
  } else {
    const double delta_old = ri + rj - norm(d_old);
    released_ += Model::spring_energy(c, ri * rj / (ri + rj), delta_old, h);
  }
}

template <class Model, class Shape>
[[gnu::noinline]] void Kernel<Model, Shape>::release_wall(const ParticleStore& p,
                                                          const Walls& walls, std::int32_t i,
                                                          std::int32_t element, double dt,
                                                          const double* h) {
  const WallElement& e = walls.elements()[element];
  const auto& c = coeffs_[p.material[i] * n_mat_ + e.material];
  if constexpr (kArmsApart) {
    // The shape's geometry now, taken back along the closing velocity of its contact point.
    std::array<double, kShapeWidth> h_old, h_new;
    for (std::size_t s = 0; s < kShapeWidth; ++s) h_old[s] = h[kModelWidth + s];
    WallContact wc;
    if constexpr (kSemiAxes)
      wc = Shape::wall(walls, element, p.pos[i], p.radius[i], p.theta[i], form_of(p, i), h_old,
                       h_new);
    else
      wc = Shape::wall(walls, element, p.pos[i], p.radius[i], p.theta[i], h_old, h_new);
    const Vec2 v_rel = p.vel[i] + p.omega[i] * perp(wc.arm) - walls.velocity_at(e.body, wc.g.point);
    released_ += Model::spring_energy(c, wc.r_eff, wc.g.delta - dt * dot(v_rel, wc.g.n), h);
  } else {
    const WallGeometry g = Shape::wall(walls, element, p.pos[i], p.radius[i]);
    const Vec2 v_rel = p.vel[i] - walls.velocity_at(e.body, g.point);
    const double delta_old = g.delta - dt * dot(v_rel, g.n);  // closing along n, i to the wall
    released_ += Model::spring_energy(c, p.radius[i], delta_old, h);
  }
}

// The entries whose committed history holds spring energy (after a rebuild: rare).
template <class Model, class Shape>
void Kernel<Model, Shape>::find_live(const PairList& pl, const WallPairList& wl) {
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
template <class Model, class Shape>
void Kernel<Model, Shape>::release_ended(const ParticleStore& p, const Walls& walls,
                                         const PairList& pl, const WallPairList& wl, double dt) {
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

}  // namespace dem2d::kernels
