// The superellipse as a particle shape of the force kernel (docs/extending.md, "A particle shape"):
// the slot's narrow phase on the geometry of core/shape/superellipse.hpp. Its arms leave the
// normal, so it takes the general path of Kernel<Model, Shape>; each body's semi-axes a, b and
// exponent n come from the store's shape fields (ParticleStore::enable_shape), gathered beside
// the spins and angles (kSemiAxes: gather_frames_scalar, and the wall gather).
//
// The pair's contact is the penetration depth (superellipse.hpp, contact_depth): a 1D
// minimisation over the normal's angle. The midway point (contact_pair) is not solved here: its
// normal differs from the penetration depth's at first order in the overlap, so it is no more
// than a warm start, and the last step's normal is a better and cheaper one (2-3 evaluations of
// the support points instead of a 3x3 Newton solve and then the minimisation).
//
// History: slot 0, the pair's normal angle less theta_i at its last step: the warm start of the
// next step's solve (it follows i's rotation, so a contact that keeps its pose relative to i
// starts at its solution); walls leave it unused (their solves are closed form or start from the
// body's pose). Slot 1, R* of the contact: taken at its first step and kept for its life (pairs
// and walls); 0 means a new contact (a cold start, and R* taken afresh).
//
// Arms: a pair's two arms end at one point, the contact point midway between the two surface
// points (contact_depth's `point`), so the torques a_i x F and a_j x (-F) keep angular momentum
// to rounding; the disc's own kernel takes r_i n and -r_j n instead (each body's own surface
// point, delta n apart), so round superellipses differ from its pairs by O(delta / r) (relative
// 2e-4 in force, 1.5e-3 in torque in tests/core/test_superellipse_shape.cpp). A wall's arm ends
// at the body's deepest point, as the disc's r n: against walls round superellipses are discs.
// R*: r_i r_j / (r_i + r_j) from the two curvature radii at the surface points (capped, see
// superellipse.hpp), against a wall the body's own, at the contact's first step, then frozen for
// the contact's life (history slot 1). With R* following the turning bodies the Hertz force
// 4/3 E* sqrt(R*) delta^3/2 would not be the gradient of a potential, and the energy stored
// (8/15 E* sqrt(R*) delta^5/2) would not be the work done: an elastic ellipse bouncing in a box
// drifts by a few 1e-3 of its energy over 48 impacts, against 2e-6 with R* frozen (53 impacts). The
// consequence: a long-lasting contact (a body rolling or rocking on a wall or a neighbour) keeps
// the R* of its first touch however far its contact point moves along the surface, until the
// bodies part.
//
// Masses and inertias: the superellipsoid's (ParticleStore::add_shaped). contact_inertia (the
// rolling models' I + m r^2 about the contact point) is the disc's with the bounding radius:
// exact for a disc, an estimate for an elongated body.
//
// A pair whose bounding circles (the store's radii) are apart is apart; so is one for which the
// cold start's coarse search (from the line of centres outwards) or an iterate of the depth's
// minimisation finds a separating axis: the search stops there (most pairs of a charge whose
// bounding circles overlap do not touch, and are never warm). For two ellipses (n = 2) the kernel
// remembers that axis for the pair (per pair-list entry, apart from the histories: a pair apart
// has none) and hands it back at the next evaluation, where it is tried first (contact_depth,
// DepthStart::axis): bodies move little in a step, so it mostly still separates them. It only
// ever proves a pair apart, so the contacts found are the same with or without it (a rebuilt list
// or a migrated pair loses it, which costs time only); for n > 2 it is not used (see
// DepthStart). Each body's cos and sin of its angle come from the kernel too, taken once per body
// and evaluation. Unconverged solves (the depth's minimisation, the shell's iteration): counted in
// SuperEllipseShape::stats() (this process), with the number of solves, the depth's evaluations
// and their histogram per solve (a kernel call's pair counts added once at its end); an
// unconverged pair keeps the last iterate (an overlap along a direction near the normal).
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
      {{"normal_angle", "rad",
        "warm start: the pair's normal angle less theta_i at its last step (walls: unused)"},
       {"r_star", "m", "R* of the contact's first step, kept for its life (0: a new contact)"}}};

  // The pair solves' histogram of depth evaluations: bins of 1, 2, 3, 4, 5-8, 9-16 and 17 or more
  // evaluations (kEvaluationBinLabels), bin_of(evaluations) the bin of a solve.
  static constexpr int kEvaluationBins = 7;
  static constexpr std::array<const char*, kEvaluationBins> kEvaluationBinLabels{
      "1", "2", "3", "4", "5-8", "9-16", "17+"};
  static constexpr int bin_of(int evaluations) {
    return evaluations <= 4    ? std::max(evaluations, 1) - 1
           : evaluations <= 8  ? 4
           : evaluations <= 16 ? 5
                               : 6;
  }

  // Solves and their failures, since the start of the process (or the last reset).
  struct Stats {
    std::atomic<std::int64_t> pair_solves{0}, pair_unconverged{0}, pair_iterations{0};
    std::atomic<std::int64_t> pair_cold{0};  // pair solves from a cold start (new contacts)
    std::atomic<std::int64_t> wall_solves{0}, wall_unconverged{0};
    // Pair solves by their depth evaluations (bin_of): the bins add up to pair_solves.
    std::array<std::atomic<std::int64_t>, kEvaluationBins> pair_evaluation_bins{};
  };
  static Stats& stats() {
    static Stats s;
    return s;
  }
  static void reset_stats() {
    Stats& s = stats();
    s.pair_solves = s.pair_unconverged = s.pair_iterations = s.pair_cold = 0;
    s.wall_solves = s.wall_unconverged = 0;
    for (std::atomic<std::int64_t>& b : s.pair_evaluation_bins) b = 0;
  }
  // A call's own counts, added to stats() once at its end.
  struct Tally {
    std::int64_t solves = 0, unconverged = 0, iterations = 0, cold = 0;
    std::array<std::int64_t, kEvaluationBins> bins{};
    void flush() const {
      if (solves == 0) return;
      Stats& st = stats();
      st.pair_solves.fetch_add(solves, std::memory_order_relaxed);
      st.pair_iterations.fetch_add(iterations, std::memory_order_relaxed);
      for (int b = 0; b < kEvaluationBins; ++b)
        if (bins[b] > 0) st.pair_evaluation_bins[b].fetch_add(bins[b], std::memory_order_relaxed);
      if (unconverged > 0) st.pair_unconverged.fetch_add(unconverged, std::memory_order_relaxed);
      if (cold > 0) st.pair_cold.fetch_add(cold, std::memory_order_relaxed);
    }
  };

  template <class T>
  [[gnu::always_inline]] static T contact_inertia(T m, T r) {
    return Disc::contact_inertia(m, r);
  }

  // One pair of bodies: i at the origin, j at d = (dx, dy), bounding radii ri, rj, angles th_i,
  // th_j with their rotations (cos, sin) rot_i, rot_j (zero: taken from the angles). Lanes out
  // of contact (bounding circles apart, or bodies apart) return delta <= 0 and zero history;
  // bodies apart also their separating axis (axis_x, axis_y), which the caller may hand back as
  // `axis` at the next evaluation (zero: none), a cold start's first try.
  static PairContactT<double> pair_one(double dx, double dy, double ri, double rj, double th_i,
                                       double th_j, Vec2 rot_i, Vec2 rot_j, const SuperEllipse& si,
                                       const SuperEllipse& sj, Vec2 axis, double h0, double h1,
                                       double& f0, double& f1, Tally& tally) {
    PairContactT<double> g{};
    f0 = f1 = 0.0;
    g.r_eff = 1.0;
    // Bounding circles apart: apart (the kernel's gather already leaves out such pairs; other
    // callers need not).
    if (rounded(dx * dx) + rounded(dy * dy) >= (ri + rj) * (ri + rj)) {
      g.delta = -1.0;
      g.nx = 1.0;
      return g;
    }
    const bool warm = h1 > 0.0;  // a contact of the last step: its normal and R*
    const DepthStart start{warm, h0 + th_i, ri, rj, axis};
    const SuperPairContact c = contact_depth(si, SuperPose{{0.0, 0.0}, th_i, rot_i}, sj,
                                             SuperPose{{dx, dy}, th_j, rot_j}, start);
    g.delta = c.delta;
    g.nx = c.n.x;
    g.ny = c.n.y;
    if (!(c.delta > 0.0)) {
      if (!c.candidate) {
        g.nx = 1.0;
      } else if (c.delta < 0.0 && si.n == 2.0 && sj.n == 2.0) {  // c.n separates the ellipses
        g.axis_x = c.n.x;
        g.axis_y = c.n.y;
      }
      return g;
    }
    ++tally.solves;
    tally.cold += warm ? 0 : 1;
    tally.iterations += c.depth_iterations;
    ++tally.bins[bin_of(c.depth_iterations)];
    if (!c.converged) ++tally.unconverged;
    g.r_eff = warm ? h1 : c.rho_i * c.rho_j / (c.rho_i + c.rho_j);
    g.aix = c.arm_i.x;
    g.aiy = c.arm_i.y;
    g.ajx = c.arm_j.x;
    g.ajy = c.arm_j.y;
    g.arm_i = norm(c.arm_i);
    g.arm_j = norm(c.arm_j);
    f0 = c.angle - th_i;
    f1 = g.r_eff;
    return g;
  }

  template <class T>
  static PairContactT<T> pair(const PairInputT<T>& in, const std::array<T, 2>& old,
                              std::array<T, 2>& fresh) {
    Tally tally;
    if constexpr (std::is_same_v<T, double>) {
      const PairContactT<double> g =
          pair_one(in.dx, in.dy, in.ri, in.rj, in.th_i, in.th_j, {in.cos_i, in.sin_i},
                   {in.cos_j, in.sin_j}, {in.ai, in.bi, in.ni}, {in.aj, in.bj, in.nj},
                   {in.axis_x, in.axis_y}, old[0], old[1], fresh[0], fresh[1], tally);
      tally.flush();
      return g;
    } else {
      constexpr std::size_t L = T::size();
      std::array<PairContactT<double>, L> g;
      std::array<double, L> f0, f1;
      for (std::size_t l = 0; l < L; ++l) {
        // The kernel pads a pack with copies of its last contact: solved once.
        if (l > 0 && in.dx[l] == in.dx[l - 1] && in.dy[l] == in.dy[l - 1] &&
            in.ri[l] == in.ri[l - 1] && in.rj[l] == in.rj[l - 1] && in.th_i[l] == in.th_i[l - 1] &&
            in.th_j[l] == in.th_j[l - 1] && in.ai[l] == in.ai[l - 1] && in.bi[l] == in.bi[l - 1] &&
            in.ni[l] == in.ni[l - 1] && in.aj[l] == in.aj[l - 1] && in.bj[l] == in.bj[l - 1] &&
            in.nj[l] == in.nj[l - 1] && old[0][l] == old[0][l - 1] && old[1][l] == old[1][l - 1]) {
          g[l] = g[l - 1];
          f0[l] = f0[l - 1];
          f1[l] = f1[l - 1];
          continue;
        }
        g[l] = pair_one(in.dx[l], in.dy[l], in.ri[l], in.rj[l], in.th_i[l], in.th_j[l],
                        {in.cos_i[l], in.sin_i[l]}, {in.cos_j[l], in.sin_j[l]},
                        {in.ai[l], in.bi[l], in.ni[l]}, {in.aj[l], in.bj[l], in.nj[l]},
                        {in.axis_x[l], in.axis_y[l]}, old[0][l], old[1][l], f0[l], f1[l], tally);
      }
      tally.flush();
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
      out.axis_x = col(&PairContactT<double>::axis_x);
      out.axis_y = col(&PairContactT<double>::axis_y);
      fresh[0] = T([&](auto l) { return f0[l]; });
      fresh[1] = T([&](auto l) { return f1[l]; });
      return out;
    }
  }

  // Body at x (bounding radius r, angle theta, form s) against wall element `element`: the
  // shell's circle by contact_inside_circle, a segment (and its ends: lifter corners) by
  // contact_segment. The bounding circle's cheap test first.
  static WallContact wall(const Walls& walls, int element, Vec2 x, double r, double theta,
                          const SuperEllipse& s, const std::array<double, 2>& old,
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
    WallContact out = c.contact;
    if (out.g.delta > 0.0) {
      if (old[1] > 0.0) out.r_eff = old[1];  // R* of the contact's first step
      fresh[1] = out.r_eff;
    }
    return out;
  }
};

}  // namespace dem2d
