// The outline of a superellipse as a polygon, for pictures (snapshots.xmf's outline grid): K
// points of the curve |x/a|^n + |y/b|^n = 1 from its parametric form
//   x = a sgn(cos t) |cos t|^(2/n),  y = b sgn(sin t) |sin t|^(2/n),  t = 2 pi k / K,
// counter-clockwise from the body's +x axis, turned by theta and moved to the centre
// (superellipse.hpp's frames: lab = centre + rotate(body, theta)). The curve is convex, so the
// polygon lies inside it; the points crowd where the curve bends (a rounded box's corners) and
// thin out along its flat faces. For n = 2 the polygon is an affine image of the regular K-gon:
// its area is (K / 2) a b sin(2 pi / K).
//
// K is a multiple of 4: cos t and sin t come from the first quadrant's angles turned by whole
// quarter turns, so the points at t = 0, pi/2, pi, 3pi/2 lie exactly on the axes (a cos t of
// 6e-17 raised to 2/n = 0.04 would otherwise put one at x = 0.22 a). Pure arithmetic, the same
// bits for the same inputs on every rank.
#pragma once

#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>

#include "core/base/vec2.hpp"
#include "core/shape/superellipse.hpp"

namespace dem2d {

// The outline's points into `out` (K = out.size(), a multiple of 4).
inline void superellipse_outline(const SuperEllipse& s, Vec2 centre, double theta,
                                 std::span<Vec2> out) {
  const std::size_t k_total = out.size();
  const std::size_t quarter = k_total / 4;
  const double power = 2.0 / s.n;
  const Vec2 turn{std::cos(theta), std::sin(theta)};
  const auto scaled = [&](double c) { return std::copysign(std::pow(std::fabs(c), power), c); };
  for (std::size_t k = 0; k < k_total; ++k) {
    const std::size_t q = k / quarter, r = k % quarter;
    const double phi =
        2.0 * std::numbers::pi * static_cast<double>(r) / static_cast<double>(k_total);
    const double c0 = r == 0 ? 1.0 : std::cos(phi), s0 = r == 0 ? 0.0 : std::sin(phi);
    const double c = q == 0 ? c0 : q == 1 ? -s0 : q == 2 ? -c0 : s0;
    const double sn = q == 0 ? s0 : q == 1 ? c0 : q == 2 ? -s0 : -c0;
    const Vec2 body{s.a * scaled(c), s.b * scaled(sn)};
    out[k] = centre + rotate(body, turn);
  }
}

}  // namespace dem2d
