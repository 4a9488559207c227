// The superellipse as a particle shape of the force kernel (docs/extending.md, "A particle shape"):
// the slot's narrow phase on the geometry of core/shape/superellipse.hpp. Its arms leave the
// normal, so it takes the general path of Kernel<Model, Shape>; each body's semi-axes a, b and
// exponent n come from the store's shape fields (ParticleStore::enable_shape), gathered beside
// the spins and angles (kSemiAxes: gather_frames_scalar, and the wall gather).
//
// History: the midway point of the pair's last solve, in the body frame of i (x_i at the origin,
// turned back by theta_i), the warm start of the next step's solve: it follows i's translation
// and rotation, so a contact that keeps its pose relative to i starts at its solution. (0, 0)
// (a new contact, or the last solve did not converge) means a cold start. Wall contacts keep the
// two slots unused (zero): their solves are closed form or start from the body's pose.
//
// Arms: a pair's two arms end at one point, the contact point midway between the two surface
// points (contact_pair's `point`), so the torques a_i x F and a_j x (-F) keep angular momentum
// to rounding; the disc's own kernel takes r_i n and -r_j n instead (each body's own surface
// point, delta n apart), so round superellipses differ from its pairs by O(delta / r) (relative
// 2e-4 in force, 1.5e-3 in torque in tests/core/test_superellipse_shape.cpp). A wall's arm ends
// at the body's deepest point, as the disc's r n: against walls round superellipses are discs.
// R*: r_i r_j / (r_i + r_j) from the two curvature radii at the surface points (capped, see
// superellipse.hpp), against a wall the body's own.
//
// Masses and inertias: the superellipsoid's (ParticleStore::add_shaped). contact_inertia (the
// rolling models' I + m r^2 about the contact point) is the disc's with the bounding radius:
// exact for a disc, an estimate for an elongated body.
//
// A pair whose support points along the line of centres do not reach each other is apart (no
// solve). Unconverged solves (the midway point's Newton, the shell's iteration): counted in
// SuperEllipseShape::stats() (this process), with the number of solves; the pair's fallback is
// contact_pair's (the line of centres and the support points along it).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "core/base/history_slot.hpp"
#include "core/fast/simd.hpp"
#include "core/shape/disc.hpp"
#include "core/shape/superellipse.hpp"

namespace dem2d {

struct SuperEllipseShape {
  static constexpr bool kArmsAlongNormal = false;
  static constexpr bool kSemiAxes = true;  // reads each body's a, b, n (PairInputT, wall)
  static constexpr std::array<HistorySlot, 2> kHistory{
      {{"midway_x", "m", "warm start: the pair's midway point, x in the body frame of i"},
       {"midway_y", "m", "warm start: the pair's midway point, y in the body frame of i"}}};

  // Solves and their failures, since the start of the process (or the last reset).
  struct Stats {
    std::atomic<std::int64_t> pair_solves{0}, pair_unconverged{0}, pair_iterations{0};
    std::atomic<std::int64_t> wall_solves{0}, wall_unconverged{0};
  };
  static Stats& stats() {
    static Stats s;
    return s;
  }
  static void reset_stats() {
    Stats& s = stats();
    s.pair_solves = s.pair_unconverged = s.pair_iterations = 0;
    s.wall_solves = s.wall_unconverged = 0;
  }

  template <class T>
  [[gnu::always_inline]] static T contact_inertia(T m, T r) {
    return Disc::contact_inertia(m, r);
  }

  // One pair of bodies: i at the origin, j at d = (dx, dy). Lanes out of contact (bounding
  // circles apart, or bodies apart) return delta <= 0 and zero history.
  static PairContactT<double> pair_one(double dx, double dy, double th_i, double th_j,
                                       const SuperEllipse& si, const SuperEllipse& sj, double h0,
                                       double h1, double& f0, double& f1) {
    PairContactT<double> g{};
    f0 = f1 = 0.0;
    // The cheap test first: the two support points along the line of centres. Apart along that
    // axis, the bodies are apart (a third of the candidates of a drum of ellipses, each spared
    // the Newton solve).
    const double dist = std::sqrt(rounded(dx * dx) + rounded(dy * dy));
    if (dist > 0.0) {
      const Vec2 u{dx / dist, dy / dist};
      const double reach = dot(support_lab(si, {0.0, 0.0}, th_i, u), u) +
                           dot(support_lab(sj, {0.0, 0.0}, th_j, -u), -u);
      if (reach < dist) {
        g.delta = reach - dist;
        g.nx = u.x;
        g.ny = u.y;
        g.r_eff = 1.0;
        return g;
      }
    }
    const double ci = std::cos(th_i), sn = std::sin(th_i);
    Vec2 warm{};
    const bool have_warm = h0 != 0.0 || h1 != 0.0;
    if (have_warm) warm = rotate(Vec2{h0, h1}, Vec2{ci, sn});
    const SuperPairContact c = contact_pair(si, SuperPose{{0.0, 0.0}, th_i}, sj,
                                            SuperPose{{dx, dy}, th_j}, have_warm ? &warm : nullptr);
    g.delta = c.delta;
    if (!c.candidate) {
      g.delta = std::min(g.delta, 0.0);
      g.nx = 1.0;
      g.r_eff = 1.0;
      return g;
    }
    Stats& st = stats();
    st.pair_solves.fetch_add(1, std::memory_order_relaxed);
    st.pair_iterations.fetch_add(c.iterations, std::memory_order_relaxed);
    if (!c.converged) st.pair_unconverged.fetch_add(1, std::memory_order_relaxed);
    g.nx = c.n.x;
    g.ny = c.n.y;
    g.r_eff = c.rho_i * c.rho_j / (c.rho_i + c.rho_j);
    g.aix = c.arm_i.x;
    g.aiy = c.arm_i.y;
    g.ajx = c.arm_j.x;
    g.ajy = c.arm_j.y;
    g.arm_i = norm(c.arm_i);
    g.arm_j = norm(c.arm_j);
    if (c.converged) {  // the midway point into i's body frame
      const Vec2 body = rotate(c.midway, Vec2{ci, -sn});
      f0 = body.x;
      f1 = body.y;
    }
    return g;
  }

  template <class T>
  static PairContactT<T> pair(const PairInputT<T>& in, const std::array<T, 2>& old,
                              std::array<T, 2>& fresh) {
    if constexpr (std::is_same_v<T, double>) {
      return pair_one(in.dx, in.dy, in.th_i, in.th_j, {in.ai, in.bi, in.ni}, {in.aj, in.bj, in.nj},
                      old[0], old[1], fresh[0], fresh[1]);
    } else {
      constexpr std::size_t L = T::size();
      std::array<PairContactT<double>, L> g;
      std::array<double, L> f0, f1;
      for (std::size_t l = 0; l < L; ++l) {
        // The kernel pads a pack with copies of its last contact: solved once.
        if (l > 0 && in.dx[l] == in.dx[l - 1] && in.dy[l] == in.dy[l - 1] &&
            in.th_i[l] == in.th_i[l - 1] && in.th_j[l] == in.th_j[l - 1] &&
            in.ai[l] == in.ai[l - 1] && in.bi[l] == in.bi[l - 1] && in.ni[l] == in.ni[l - 1] &&
            in.aj[l] == in.aj[l - 1] && in.bj[l] == in.bj[l - 1] && in.nj[l] == in.nj[l - 1] &&
            old[0][l] == old[0][l - 1] && old[1][l] == old[1][l - 1]) {
          g[l] = g[l - 1];
          f0[l] = f0[l - 1];
          f1[l] = f1[l - 1];
          continue;
        }
        g[l] = pair_one(in.dx[l], in.dy[l], in.th_i[l], in.th_j[l], {in.ai[l], in.bi[l], in.ni[l]},
                        {in.aj[l], in.bj[l], in.nj[l]}, old[0][l], old[1][l], f0[l], f1[l]);
      }
      const auto col = [&](auto field) { return T([&](auto l) { return g[l].*field; }); };
      PairContactT<T> out;
      out.delta = col(&PairContactT<double>::delta);
      out.nx = col(&PairContactT<double>::nx);
      out.ny = col(&PairContactT<double>::ny);
      out.r_eff = col(&PairContactT<double>::r_eff);
      out.arm_i = col(&PairContactT<double>::arm_i);
      out.arm_j = col(&PairContactT<double>::arm_j);
      out.aix = col(&PairContactT<double>::aix);
      out.aiy = col(&PairContactT<double>::aiy);
      out.ajx = col(&PairContactT<double>::ajx);
      out.ajy = col(&PairContactT<double>::ajy);
      fresh[0] = T([&](auto l) { return f0[l]; });
      fresh[1] = T([&](auto l) { return f1[l]; });
      return out;
    }
  }

  // Body at x (bounding radius r, angle theta, form s) against wall element `element`: the
  // shell's circle by contact_inside_circle, a segment (and its ends: lifter corners) by
  // contact_segment. The bounding circle's cheap test first.
  static WallContact wall(const Walls& walls, int element, Vec2 x, double r, double theta,
                          const SuperEllipse& s, const std::array<double, 2>& /*old*/,
                          std::array<double, 2>& fresh) {
    fresh = {0.0, 0.0};
    WallContact none;
    none.g.delta = -1.0;
    if (!Disc::touches_wall(walls, element, x, r)) return none;
    const WallElement& e = walls.elements()[element];
    const SuperWallContact c =
        e.kind == WallKind::kCircle
            ? contact_inside_circle(s, x, theta, walls.circle_center(e), e.radius)
            : contact_segment(s, x, theta, e.a, e.b);
    Stats& st = stats();
    st.wall_solves.fetch_add(1, std::memory_order_relaxed);
    if (!c.converged) st.wall_unconverged.fetch_add(1, std::memory_order_relaxed);
    return c.contact;
  }
};

}  // namespace dem2d
