// The disc: the particle shape of the thesis's balls and ore, a sphere of radius r whose centre
// moves in the plane (docs/models.md, "Bodies and frame"). A shape owns what depends on the body's
// form:
//   mass, inertia             from its size and density (a 3D sphere: 4/3 pi r^3 rho, 2/5 m r^2)
//   rotational_energy         1/2 I w^2 with its own inertia
//   contact_inertia           I + m r^2 about the contact point (rolling models)
//   pair / clear_of_pair      the narrow phase of two bodies: overlap, normal, contact arms, R*
//   wall / touches_wall       the narrow phase against a wall element (circle or segment)
// Everything that needs one of these asks the shape; no other file writes them again.
//
// Contact arms: the contact point seen from each centre. A disc's arms lie along the normal (from
// i: +arm_i n, from j: -arm_j n), so the torque of a force f_t t - f_n n about its centre is
// arm f_t exactly as arm x force, and the velocity of its surface point is v + w arm t: the force
// kernel takes those forms for a shape with kArmsAlongNormal. A shape whose arms leave the normal
// (kArmsAlongNormal = false) returns them as vectors, and the kernel takes arm x force and
// v + w x arm; such a shape may also keep history of its own in each contact (kHistory, after
// the contact model's slots). docs/extending.md, "A particle shape", lists what it declares.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/base/history_slot.hpp"
#include "core/base/vec2.hpp"
#include "core/geometry/walls.hpp"

namespace dem2d {

// What a shape's narrow phase finds for two bodies i and j (T: double, or a pack of contacts).
template <class T>
struct PairContactT {
  T delta;         // overlap (> 0 in contact)
  T nx, ny;        // unit normal from i towards j
  T r_eff;         // effective radius of curvature at the contact (Hertz R*)
  T arm_i, arm_j;  // lengths of the contact arms along the normal (kArmsAlongNormal)
  // The arms as vectors, contact point minus each centre (shapes without kArmsAlongNormal).
  T aix{}, aiy{}, ajx{}, ajy{};
  // A separating axis (unit, lab frame) of a pair found apart, for the next evaluation
  // (PairInputT::axis_x, axis_y; shapes that remember one), else zero.
  T axis_x{}, axis_y{};
};

// What the narrow phase of a shape without kArmsAlongNormal reads for two bodies i and j: the
// centres' offset d = x_j - x_i (dist2 = |d|^2), their radii (bounding circles: the broad phase
// and the gather's first test use them) and their angles.
// A shape with semi-axes (kSemiAxes, the superellipse) reads each body's a, b and exponent n
// too, each body's cos and sin of its angle (taken once per body and evaluation), and the
// separating axis the pair's last evaluation found (PairContactT::axis_x, axis_y; zero: none);
// other shapes leave them unset.
template <class T>
struct PairInputT {
  T dx, dy, dist2;
  T ri, rj;
  T th_i, th_j;
  T ai{}, bi{}, ni{}, aj{}, bj{}, nj{};
  T cos_i{}, sin_i{}, cos_j{}, sin_j{};
  T axis_x{}, axis_y{};
};

// Whether a shape reads each body's semi-axes and exponent (PairInputT; its wall takes them).
template <class Shape>
inline constexpr bool kShapeHasSemiAxes = requires {
  requires Shape::kSemiAxes;
};

// Closest contact of a body with one wall element at the current time.
struct WallGeometry {
  double delta = 0.0;  // overlap (> 0 in contact); for the reach test: r - distance to surface
  Vec2 n{};            // unit normal from the body's centre towards the wall
  Vec2 point{};        // contact point on the wall
};

// A shape without kArmsAlongNormal against a wall element: the geometry, the arm (contact point
// minus centre) and the radius of curvature at the contact (Hertz R* against a flat wall).
struct WallContact {
  WallGeometry g;
  Vec2 arm{};
  double r_eff = 0.0;
};

struct Disc {
  static constexpr bool kArmsAlongNormal = true;
  static constexpr std::array<HistorySlot, 0> kHistory{};  // none of its own

  static double mass(double r, double density) {
    return 4.0 / 3.0 * std::numbers::pi * r * r * r * density;
  }
  static double inertia(double m, double r) { return 0.4 * m * r * r; }
  static double rotational_energy(double m, double r, double w) {
    return 0.5 * inertia(m, r) * w * w;
  }
  // I + m r^2 = 7/5 m r^2: the moment of inertia about the contact point.
  template <class T>
  [[gnu::always_inline]] static T contact_inertia(T m, T r) {
    return 1.4 * m * r * r;
  }

  // Two discs, centres d = x_j - x_i apart (dist2 = |d|^2), radii ri and rj.
  template <class T>
  [[gnu::always_inline]] static PairContactT<T> pair(T dx, T dy, T dist2, T ri, T rj) {
    using std::sqrt;  // a pack's sqrt is found beside its type (std::experimental)
    const T dist = sqrt(dist2);
    const T inv = 1.0 / dist;
    const T rsum = ri + rj;
    return {rsum - dist, inv * dx, inv * dy, ri * rj / rsum, ri, rj};
  }

  // A disc of radius r inside a circle of radius R, its centre at d from the circle's centre
  // (d2 = |d|^2): clear of it (no contact), without the square root of the full geometry.
  [[gnu::always_inline]] static bool clear_inside_circle(double R, double r, double d2) {
    const double inner = R - r;
    return inner > 0.0 && d2 <= inner * inner;
  }
  // delta = |d| + r - R, the normal from the disc towards the shell, the point on the shell
  // (circle centre c, dist = |d|).
  [[gnu::always_inline]] static WallGeometry inside_circle(Vec2 c, double R, Vec2 d, double dist,
                                                           double r) {
    WallGeometry g;
    g.n = dist > 0.0 ? (1.0 / dist) * d : Vec2{1.0, 0.0};
    g.delta = dist + r - R;
    g.point = c + R * g.n;
    return g;
  }
  // Against a segment [a, b] with rounded ends: the closest point q.
  static WallGeometry segment(Vec2 a, Vec2 b, Vec2 x, double r) {
    WallGeometry g;
    const Vec2 ab = b - a;
    const double len2 = norm2(ab);
    double s = len2 > 0.0 ? dot(x - a, ab) / len2 : 0.0;
    s = std::clamp(s, 0.0, 1.0);
    const Vec2 q = a + s * ab;
    const Vec2 d = q - x;
    const double dist = norm(d);
    g.n = dist > 0.0 ? (1.0 / dist) * d : perp(ab) * (1.0 / std::sqrt(len2));
    g.delta = r - dist;
    g.point = q;
    return g;
  }
  // A disc at x of radius r against element `element` of the walls at their current time.
  static WallGeometry wall(const Walls& walls, int element, Vec2 x, double r) {
    const WallElement& e = walls.elements()[element];
    if (e.kind != WallKind::kCircle) return segment(e.a, e.b, x, r);
    const Vec2 c = walls.circle_center(e);
    const Vec2 d = x - c;
    return inside_circle(c, e.radius, d, norm(d), r);
  }
  // Whether it overlaps the element (wall(...).delta > 0) without the square root and division
  // of the full geometry: the cheap test of the force kernel.
  static bool touches_wall(const Walls& walls, int element, Vec2 x, double r) {
    const WallElement& e = walls.elements()[element];
    if (e.kind == WallKind::kCircle)
      return !clear_inside_circle(e.radius, r, norm2(x - walls.circle_center(e)));
    const Vec2 ab = e.b - e.a;
    const double len2 = norm2(ab);
    const double s = len2 > 0.0 ? std::clamp(dot(x - e.a, ab) / len2, 0.0, 1.0) : 0.0;
    return !(norm2(e.a + s * ab - x) >= r * r);
  }
};

}  // namespace dem2d
