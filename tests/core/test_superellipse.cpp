// The superellipse's geometry (core/shape/superellipse.hpp) against independent references:
//   - support points against a brute-force sweep of the curve (and the defining condition);
//   - F, its gradient and Hessian against finite differences; the curvature radius against the
//     ellipse's closed form and the circle's radius;
//   - area, volume and inertia against 1D tanh-sinh quadratures of the sections (no Gamma
//     function), and the sphere's 4/3 pi r^3 and 2/5 m r^2 for a = b, n = 2;
//   - the pair: the midway point against its own definition found by brute force (the level sets
//     F_i = F_j = c grown until they touch); the contact against the penetration depth (the
//     minimum over directions of the overlap of the two support functions: the minimum
//     translation distance, the physical reference) and against dense polygons (8000 vertices
//     each; the exact penetration depth of two convex polygons over their edge normals); the
//     contact point against the middle of the overlap lens (printed); circles exactly; iterations
//     with and without a warm start, and a warm solve against a cold one;
//   - walls: a segment (its face, past its ends, a tilted tip crossing near an end), the drum's
//     circle and a point against dense polygons over random superellipses; a disc reproduces
//     Disc::segment and Disc::inside_circle.
// The cost per solve: bench/bm_superellipse.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <random>
#include <vector>

#include "core/shape/disc.hpp"
#include "core/shape/superellipse.hpp"

namespace dem2d {
namespace {

constexpr double kPi = std::numbers::pi;

Vec2 unit(double phi) { return {std::cos(phi), std::sin(phi)}; }

// The curve's point at polar angle t (body frame).
Vec2 polar_point(const SuperEllipse& s, double t) {
  const double c = std::cos(t), sn = std::sin(t);
  const double r =
      std::pow(std::pow(std::abs(c) / s.a, s.n) + std::pow(std::abs(sn) / s.b, s.n), -1.0 / s.n);
  return {r * c, r * sn};
}

// Golden-section search for the minimum of f on [lo, hi] (unimodal there).
template <class F>
double golden_min(F f, double lo, double hi, int steps = 90) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int k = 0; k < steps; ++k) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
    }
  }
  return 0.5 * (lo + hi);
}

// Minimum over the angle of f: a sweep of `count` angles, then golden section about the best.
template <class F>
double sweep_min(F f, int count = 1000) {
  double best = 0.0, fb = f(0.0);
  const double h = 2.0 * kPi / count;
  for (int k = 1; k < count; ++k)
    if (const double v = f(k * h); v < fb) fb = v, best = k * h;
  return golden_min(f, best - h, best + h);
}

const double kExponents[] = {2.0, 2.5, 4.0, 8.0, 10.0};

// ---- Support ------------------------------------------------------------------------------------

TEST(SuperEllipse, SupportIsTheFarthestPointOfTheCurve) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst_value = 0.0, worst_point = 0.0, worst_condition = 0.0;
  for (double n : kExponents)
    for (double aspect : {1.0, 1.7, 2.5, 4.0})
      for (int k = 0; k < 40; ++k) {
        const SuperEllipse s{0.01 * aspect, 0.01, n};
        const Vec2 u = unit(2.0 * kPi * U(rng));
        const Vec2 p = support(s, u);
        // Brute force: the largest u . q over the curve (sweep of the polar angle, refined).
        const auto minus_reach = [&](double t) { return -dot(u, polar_point(s, t)); };
        const Vec2 q = polar_point(s, sweep_min(minus_reach, 4000));
        worst_value = std::max(worst_value, std::abs(dot(u, p) - dot(u, q)) / s.a);
        worst_point = std::max(worst_point, norm(p - q) / s.a);
        // The defining conditions: on the curve, its normal along u.
        const Vec2 g = gradient(s, p);
        EXPECT_NEAR(implicit(s, p), 0.0, 1e-13);
        worst_condition = std::max(worst_condition, std::abs(cross(g, u)) / norm(g));
        EXPECT_GT(dot(g, u), 0.0);
      }
  std::printf("support: |u.p - brute| <= %.2e a, |p - brute| <= %.2e a, normal off u %.2e\n",
              worst_value, worst_point, worst_condition);
  EXPECT_LT(worst_value, 1e-12);
  // The point of a maximum is found less sharply than its value (u . q is flat there: a value
  // to 1e-16 places the point to ~1e-8 sqrt(rho / a), worse on the flat faces of large n).
  EXPECT_LT(worst_point, 1e-6);
  EXPECT_LT(worst_condition, 1e-12);
  // support_curvature: the same point and the curvature there, without the extra pow.
  for (double n : {2.0, 2.5, 4.0, 10.0})
    for (int k = 0; k < 64; ++k) {
      const SuperEllipse s{0.03, 0.01, n};
      const Vec2 u = unit(2.0 * kPi * (k + 0.25) / 64);
      const SupportCurvature sc = support_curvature(s, u);
      const Vec2 p = support(s, u);
      EXPECT_LT(norm(sc.p - p), 1e-17);
      EXPECT_NEAR(sc.kappa, curvature(s, p), 1e-12 * curvature(s, p));
    }
  // The lab frame: turned and moved.
  const SuperEllipse s{0.03, 0.01, 4.0};
  const Vec2 c{0.2, -0.1};
  const double th = 0.7;
  const Vec2 u = unit(1.9);
  const Vec2 p = support_lab(s, c, th, u);
  const Vec2 pb = support(s, rotate(u, -th));
  EXPECT_NEAR(norm(p - (c + rotate(pb, th))), 0.0, 1e-15);
}

// ---- Implicit function and curvature -----------------------------------------------------------

TEST(SuperEllipse, DerivativesMatchFiniteDifferences) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1.3, 1.3);
  for (double n : kExponents)
    for (int k = 0; k < 50; ++k) {
      const SuperEllipse s{0.02, 0.01, n};
      const Vec2 p{s.a * U(rng), s.b * U(rng)};
      const ImplicitValue v = evaluate(s, p);
      const double h = 1e-6 * s.b;
      const Vec2 ex{h, 0.0}, ey{0.0, h};
      const Vec2 gx = (0.5 / h) * Vec2{implicit(s, p + ex) - implicit(s, p - ex),
                                       implicit(s, p + ey) - implicit(s, p - ey)};
      const double gscale = norm(v.grad) + 1.0 / s.b;
      EXPECT_NEAR(v.grad.x, gx.x, 1e-7 * gscale);
      EXPECT_NEAR(v.grad.y, gx.y, 1e-7 * gscale);
      const double hxx = (gradient(s, p + ex).x - gradient(s, p - ex).x) / (2.0 * h);
      const double hyy = (gradient(s, p + ey).y - gradient(s, p - ey).y) / (2.0 * h);
      const double hxy = (gradient(s, p + ey).x - gradient(s, p - ey).x) / (2.0 * h);
      const double hscale = std::abs(v.hess.x) + std::abs(v.hess.y) + 1.0 / (s.b * s.b);
      EXPECT_NEAR(v.hess.x, hxx, 1e-6 * hscale);
      EXPECT_NEAR(v.hess.y, hyy, 1e-6 * hscale);
      EXPECT_NEAR(hxy, 0.0, 1e-6 * hscale);
    }
  // The axes and the centre: finite for every n (u^(n-2) at u = 0).
  for (double n : kExponents) {
    const SuperEllipse s{0.02, 0.01, n};
    const ImplicitValue v = evaluate(s, {0.0, 0.01});
    EXPECT_DOUBLE_EQ(v.f, 0.0);
    EXPECT_EQ(v.hess.x, n == 2.0 ? 2.0 / (s.a * s.a) : 0.0);
    EXPECT_TRUE(std::isfinite(evaluate(s, {0.0, 0.0}).hess.y));
  }
  // Far points: finite (the clamp).
  EXPECT_TRUE(std::isfinite(implicit(SuperEllipse{1e-3, 1e-3, 50.0}, {1e6, 1e6})));
}

TEST(SuperEllipse, CurvatureRadiusOfEllipseAndCircle) {
  const SuperEllipse e{0.03, 0.01, 2.0};
  for (int k = 0; k < 64; ++k) {
    const double t = 2.0 * kPi * k / 64;
    const Vec2 p{e.a * std::cos(t), e.b * std::sin(t)};
    const double q = e.a * e.a * std::sin(t) * std::sin(t) + e.b * e.b * std::cos(t) * std::cos(t);
    const double rho = q * std::sqrt(q) / (e.a * e.b);
    EXPECT_NEAR(curvature_radius(e, p), std::min(rho, kCurvatureRadiusCap * equivalent_radius(e)),
                1e-12 * rho);
    EXPECT_NEAR(curvature(e, p), 1.0 / rho, 1e-12 / rho);
  }
  const SuperEllipse c{0.01, 0.01, 2.0};
  for (int k = 0; k < 16; ++k) EXPECT_NEAR(curvature_radius(c, 0.01 * unit(0.4 * k)), 0.01, 1e-15);
  // The cap: remembered, or given.
  const double cap = curvature_radius_cap(e);
  EXPECT_DOUBLE_EQ(cap, kCurvatureRadiusCap * equivalent_radius(e));
  EXPECT_EQ(curvature_radius(e, {0.0, e.b}, cap), curvature_radius(e, {0.0, e.b}));
  EXPECT_EQ(curvature_radius(e, {0.0, e.b}, 1e-3), 1e-3);
  // The middle of a flat face: the cap.
  const SuperEllipse box{0.02, 0.01, 8.0};
  EXPECT_EQ(curvature(box, {0.0, 0.01}), 0.0);
  EXPECT_DOUBLE_EQ(curvature_radius(box, {0.0, 0.01}),
                   kCurvatureRadiusCap * equivalent_radius(box));
}

// ---- Mass and inertia ---------------------------------------------------------------------------

// Tanh-sinh quadrature of f on [0, 1]: exact to rounding for integrands with endpoint
// singularities like (1 - t^n)^(1/n). f(t, 1 - t).
template <class F>
double tanh_sinh(F f) {
  const double h = 1.0 / 64.0;
  double sum = 0.0;
  for (int k = -256; k <= 256; ++k) {
    const double t = k * h;
    const double sh = 0.5 * kPi * std::sinh(t);
    const double w = 0.5 * kPi * std::cosh(t) / (std::cosh(sh) * std::cosh(sh));
    const double x = 0.5 * (1.0 + std::tanh(sh));
    const double one_minus_x = 1.0 / (1.0 + std::exp(2.0 * sh));
    if (x <= 0.0 || one_minus_x <= 0.0) continue;
    sum += 0.5 * w * f(x);
  }
  return sum * h;
}

TEST(SuperEllipse, MassAndInertiaMatchQuadrature) {
  for (double n : {2.0, 2.5, 3.0, 4.0, 8.0, 10.0})
    for (double aspect : {1.0, 2.0, 4.0}) {
      const SuperEllipse s{0.01 * aspect, 0.01, n};
      const double c = std::min(s.a, s.b), rho = 7800.0;
      // The section at height z is the curve scaled by (1 - |z/c|^n)^(1/n).
      const auto m = [n](double p) {
        return tanh_sinh([n, p](double t) { return std::pow(1.0 - std::pow(t, n), p / n); });
      };
      const double m2 =  // int t^2 (1 - t^n)^(1/n)
          tanh_sinh([n](double t) { return t * t * std::pow(1.0 - std::pow(t, n), 1.0 / n); });
      const double a2 = 4.0 * s.a * s.b * m(1.0);
      const double vol = 2.0 * c * a2 * m(2.0);
      const double j2 = 4.0 * s.a * s.b * (s.a * s.a * m2 + s.b * s.b * m(3.0) / 3.0);
      const double iz = rho * 2.0 * c * j2 * m(4.0);
      EXPECT_NEAR(area(s), a2, 1e-12 * a2) << n;
      EXPECT_NEAR(volume(s), vol, 1e-12 * vol) << n;
      EXPECT_NEAR(inertia_z(s, rho), iz, 1e-12 * iz) << n;
      EXPECT_NEAR(mass(s, rho), rho * vol, 1e-12 * rho * vol);
      // The bounding radius: the largest |p| over a sweep of the curve, refined.
      const double t_far = sweep_min([&](double t) { return -norm(polar_point(s, t)); }, 4000);
      const double brute = norm(polar_point(s, t_far));
      EXPECT_NEAR(bounding_radius(s), brute, 1e-12 * brute) << n << " " << aspect;
      EXPECT_GE(bounding_radius(s), std::max(s.a, s.b));
    }
  // The sphere: a = b, n = 2.
  const double r = 0.013, rho = 2700.0;
  const SuperEllipse s{r, r, 2.0};
  EXPECT_NEAR(volume(s), 4.0 / 3.0 * kPi * r * r * r, 1e-14 * r * r * r);
  EXPECT_NEAR(mass(s, rho), Disc::mass(r, rho), 1e-14 * Disc::mass(r, rho));
  EXPECT_NEAR(inertia_z(s, rho), Disc::inertia(Disc::mass(r, rho), r),
              1e-14 * Disc::inertia(Disc::mass(r, rho), r));
  EXPECT_NEAR(equivalent_radius(s), r, 1e-16);
  EXPECT_NEAR(area(s), kPi * r * r, 1e-15 * r * r);
}

// ---- Pair references ----------------------------------------------------------------------------

struct Body {
  SuperEllipse s;
  SuperPose p;
};

// The two support points along the lab direction u (from i to j): i's along u, j's along -u,
// of the bodies grown by ki and kj about their centres.
struct AxisPoints {
  Vec2 pi, pj;
  double overlap;
};
AxisPoints along_axis(const Body& i, const Body& j, Vec2 u, double ki = 1.0, double kj = 1.0) {
  const Vec2 pi = i.p.centre + ki * (support_lab(i.s, {}, i.p.theta, u));
  const Vec2 pj = j.p.centre + kj * (support_lab(j.s, {}, j.p.theta, -u));
  return {pi, pj, dot(pi - pj, u)};
}

// The penetration depth: the least overlap of the support functions over all directions (the
// minimum translation distance of two convex bodies), its direction and the midpoint of the two
// support points there.
struct DepthRef {
  double depth;
  Vec2 n, point, pi;
};
DepthRef penetration(const Body& i, const Body& j, double ki = 1.0, double kj = 1.0) {
  const double phi =
      sweep_min([&](double f) { return along_axis(i, j, unit(f), ki, kj).overlap; }, 720);
  const AxisPoints a = along_axis(i, j, unit(phi), ki, kj);
  return {a.overlap, unit(phi), 0.5 * (a.pi + a.pj), a.pi};
}

// The midway point by its definition: the level sets F_i = F_j = c are the bodies grown by
// (1 + c)^(1/n) about their centres; c is the level at which they just touch (penetration depth
// 0, found by regula falsi, Illinois variant), the point is where they touch and the normal the
// touching direction.
DepthRef midway_by_definition(const Body& i, const Body& j) {
  const auto depth_at = [&](double c) {
    return penetration(i, j, std::pow(1.0 + c, 1.0 / i.s.n), std::pow(1.0 + c, 1.0 / j.s.n));
  };
  double lo = -0.5, hi = 0.0, flo = depth_at(lo).depth, fhi = depth_at(hi).depth;
  int side = 0;
  for (int k = 0; k < 60 && hi - lo > 1e-15; ++k) {
    const double c = (lo * fhi - hi * flo) / (fhi - flo);
    const double fc = depth_at(c).depth;
    if (std::abs(fc) < 1e-17) return depth_at(c);
    if (fc < 0.0) {
      lo = c, flo = fc;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      hi = c, fhi = fc;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
  }
  return depth_at(0.5 * (lo + hi));
}

// A random body: aspect 1-4, exponent 2-10 (a third of them ellipses), short axis 6-10 mm.
Body random_body(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double n = U(rng) < 1.0 / 3.0 ? 2.0 : 2.0 + 8.0 * U(rng);
  const double b = 0.006 + 0.004 * U(rng);
  return {{b * (1.0 + 3.0 * U(rng)), b, n}, {{0.0, 0.0}, 2.0 * kPi * U(rng)}};
}

// Two random bodies overlapping by a depth of 0.1-5 % (log-uniform) of the smaller bounding
// radius: j placed along a random direction, its distance corrected by Newton on the depth.
struct PairCase {
  Body i, j;
  double size;
  DepthRef mtd;
};
PairCase random_pair(std::mt19937_64& rng);
PairCase random_pair_try(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  PairCase c{random_body(rng), random_body(rng), 0.0, {}};
  c.i.p.centre = {0.1 * U(rng), 0.1 * U(rng)};
  c.size = std::min(bounding_radius(c.i.s), bounding_radius(c.j.s));
  const double target = c.size * std::exp(std::log(0.001) + U(rng) * std::log(50.0));
  const Vec2 u = unit(2.0 * kPi * U(rng));
  double D = along_axis({c.i.s, {{}, c.i.p.theta}}, {c.j.s, {{}, c.j.p.theta}}, u).overlap - target;
  for (int k = 0; k < 8; ++k) {
    c.j.p.centre = c.i.p.centre + D * u;
    c.mtd = penetration(c.i, c.j);
    if (std::abs(c.mtd.depth - target) < 1e-4 * target) break;
    D += (c.mtd.depth - target) / std::max(dot(u, c.mtd.n), 0.2);
  }
  return c;
}
// Tries until the depth is within 0.1-5 % (the correction can fail for elongated bodies side by
// side; those poses are drawn again).
PairCase random_pair(std::mt19937_64& rng) {
  for (;;) {
    const PairCase c = random_pair_try(rng);
    if (c.mtd.depth >= 0.001 * c.size && c.mtd.depth <= 0.05 * c.size) return c;
  }
}

double angle_between(Vec2 a, Vec2 b) { return std::abs(std::atan2(cross(a, b), dot(a, b))); }

// A dense polygon on the curve, counter-clockwise, in the lab frame: half its vertices evenly in
// the polar angle (dense along flat faces), half evenly in the normal's angle (dense at corners).
std::vector<Vec2> polygon(const Body& b, int count) {
  std::vector<std::pair<double, Vec2>> v;
  for (int k = 0; k < count / 2; ++k) {
    const double t = 2.0 * kPi * (k + 0.5) / (count / 2);
    const Vec2 q = polar_point(b.s, t);
    v.push_back({std::atan2(q.y, q.x), q});
    const Vec2 r = support(b.s, unit(t));
    v.push_back({std::atan2(r.y, r.x), r});
  }
  std::sort(v.begin(), v.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<Vec2> out;
  for (const auto& [ang, q] : v) out.push_back(b.p.centre + rotate(q, b.p.theta));
  return out;
}

// Index of the vertex of a convex polygon farthest along u, by climbing from `k`.
std::size_t climb(const std::vector<Vec2>& P, Vec2 u, std::size_t k) {
  const std::size_t N = P.size();
  for (bool moved = true; moved;) {
    moved = false;
    while (dot(P[(k + 1) % N], u) > dot(P[k], u)) k = (k + 1) % N, moved = true;
    while (dot(P[(k + N - 1) % N], u) > dot(P[k], u)) k = (k + N - 1) % N, moved = true;
  }
  return k;
}

// Exact penetration depth of two convex polygons: the least overlap over the edge normals of P
// (outward) and the reversed edge normals of Q (the Minkowski difference's edge normals).
DepthRef polygon_depth(const std::vector<Vec2>& P, const std::vector<Vec2>& Q) {
  DepthRef best{1e300, {}, {}, {}};
  std::size_t kp = 0, kq = 0;
  const auto consider = [&](Vec2 u) {
    kp = climb(P, u, kp);
    kq = climb(Q, -u, kq);
    const double ov = dot(P[kp] - Q[kq], u);
    if (ov < best.depth) best = {ov, u, 0.5 * (P[kp] + Q[kq]), P[kp]};
  };
  for (const auto* R : {&P, &Q})
    for (std::size_t k = 0; k < R->size(); ++k) {
      const Vec2 e = (*R)[(k + 1) % R->size()] - (*R)[k];
      const Vec2 m = (1.0 / norm(e)) * Vec2{e.y, -e.x};
      consider(R == &P ? m : -m);
    }
  return best;
}

// ---- Pair tests ---------------------------------------------------------------------------------

struct Stats {
  std::vector<double> v;
  void add(double x) { v.push_back(x); }
  double max() const { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }
  double quantile(double q) const {
    std::vector<double> s = v;
    std::sort(s.begin(), s.end());
    return s.empty() ? 0.0 : s[static_cast<std::size_t>(q * (s.size() - 1))];
  }
  void print(const char* what) const {
    std::printf("  %-46s median %.2e  95%% %.2e  99%% %.2e  max %.2e\n", what, quantile(0.5),
                quantile(0.95), quantile(0.99), max());
  }
};

void print_histogram(const char* what, const std::map<int, int>& h) {
  std::printf("  %s:", what);
  for (const auto& [it, count] : h) std::printf("  %d it: %d", it, count);
  std::printf("\n");
}

constexpr int kPairCases = 400;

// A warm start from this point after a step's motion: 1e-4 of the size and 1e-4 rad.
PairCase moved(const PairCase& c, std::mt19937_64& rng) {
  PairCase m = c;
  m.j.p.centre += (1e-4 * c.size) * unit(2.0 * kPi * std::uniform_real_distribution<>(0, 1)(rng));
  m.i.p.theta += 1e-4;
  m.j.p.theta -= 1e-4;
  return m;
}

struct PairStats {
  Stats own_angle, own_point, mtd_angle, mtd_depth, mtd_point, poly_depth, poly_angle;
  Stats lens_point, lens_midway;
  std::map<int, int> cold, warm, cold_depth, warm_depth;
  int failures = 0, fallbacks = 0, midway_fallbacks = 0;
};

// The middle of the overlap lens's chord (the two crossings of the curves: the first and last
// vertices of i's polygon inside j) against the contact point and the midway point, along the
// tangent. Printed: both leave it on near-parallel flat faces, where the support points (and the
// midway point) slide along a face for a tiny turn of the normal.
void add_lens_offset(const PairCase& c, const SuperPairContact& r, const std::vector<Vec2>& P,
                     PairStats& st) {
  const std::size_t N = P.size();
  std::vector<char> in(N);
  for (std::size_t v = 0; v < N; ++v)
    in[v] = implicit(c.j.s, rotate(P[v] - c.j.p.centre, -c.j.p.theta)) < 0.0;
  std::size_t first = N, last = N;
  for (std::size_t v = 0; v < N; ++v) {
    if (in[v] && !in[(v + N - 1) % N]) first = v;
    if (in[v] && !in[(v + 1) % N]) last = v;
  }
  if (first == N || last == N) return;
  const Vec2 mid = 0.5 * (P[first] + P[last]);
  st.lens_point.add(std::abs(dot(r.point - mid, perp(r.n))) / c.size);
  st.lens_midway.add(std::abs(dot(r.midway - mid, perp(r.n))) / c.size);
}

void add_pair_case(const PairCase& c, const SuperPairContact& r, int k, PairStats& st) {
  // The midway point against its definition; its normal is grad F_i there.
  const DepthRef own = midway_by_definition(c.i, c.j);
  const Vec2 gi =
      rotate(gradient(c.i.s, rotate(r.midway - c.i.p.centre, -c.i.p.theta)), c.i.p.theta);
  st.own_angle.add(angle_between(gi, own.n));
  st.own_point.add(norm(r.midway - own.pi) / c.size);
  // The contact against the penetration depth.
  st.mtd_angle.add(angle_between(r.n, c.mtd.n));
  st.mtd_depth.add(std::abs(r.delta - c.mtd.depth) / c.mtd.depth);
  st.mtd_point.add(norm(r.point - c.mtd.point) / c.size);
  if (r.delta <= 0.0) ++st.failures;
  if (k % 4 == 0) {  // the polygons: 8000 vertices each
    const std::vector<Vec2> P = polygon(c.i, 8000);
    const DepthRef p = polygon_depth(P, polygon(c.j, 8000));
    st.poly_depth.add(std::abs(p.depth - r.delta) / c.mtd.depth);
    st.poly_angle.add(angle_between(p.n, r.n));
    add_lens_offset(c, r, P, st);
  }
}

void print_pair_stats(const PairStats& st) {
  std::printf("pair, %d random poses (aspect 1-4, n 2-10, depth 0.1-5 %% of the size):\n",
              kPairCases);
  st.own_angle.print("midway normal vs the midway definition (rad)");
  st.own_point.print("midway point vs its definition (/ size)");
  st.mtd_angle.print("normal vs the penetration depth's (rad)");
  st.mtd_depth.print("overlap vs the penetration depth (relative)");
  st.mtd_point.print("contact point vs the depth's midpoint (/size)");
  st.poly_depth.print("overlap vs polygons' depth (relative)");
  st.poly_angle.print("normal vs polygons' normal (rad)");
  st.lens_point.print("point vs the lens's middle, along t (/ size)");
  st.lens_midway.print("midway point vs the lens's middle (/ size)");
  print_histogram("midway iterations, cold", st.cold);
  print_histogram("midway iterations, warm", st.warm);
  print_histogram("depth evaluations, cold", st.cold_depth);
  print_histogram("depth evaluations, warm", st.warm_depth);
  std::printf("  depth not converged: %d, midway not converged: %d, overlap <= 0: %d\n",
              st.fallbacks, st.midway_fallbacks, st.failures);
}

TEST(SuperEllipse, PairMatchesTheMidwayDefinitionAndThePenetrationDepth) {
  std::mt19937_64 rng(2024);
  PairStats st;
  for (int k = 0; k < kPairCases; ++k) {
    const PairCase c = random_pair(rng);
    const SuperPairContact r = contact_pair(c.i.s, c.i.p, c.j.s, c.j.p);
    ++st.cold[r.iterations];
    ++st.cold_depth[r.depth_iterations];
    st.fallbacks += !r.converged;
    st.midway_fallbacks += !r.midway_converged;
    if (!r.converged || !r.midway_converged)
      std::printf(
          "  not converged (depth %d, midway %d): %d + %d it, depth %.3g of the size, "
          "n %.2f %.2f, aspects %.2f %.2f\n",
          r.converged, r.midway_converged, r.depth_iterations, r.iterations, c.mtd.depth / c.size,
          c.i.s.n, c.j.s.n, c.i.s.a / c.i.s.b, c.j.s.a / c.j.s.b);
    add_pair_case(c, r, k, st);
    const PairCase m = moved(c, rng);
    const SuperPairContact w = contact_pair(m.i.s, m.i.p, m.j.s, m.j.p, &r.midway);
    ++st.warm[w.iterations];
    ++st.warm_depth[w.depth_iterations];
    EXPECT_TRUE(w.converged && w.midway_converged);
    EXPECT_LE(w.iterations, 3);
    // The warm solve finds the same contact as a cold one (to the angle's tolerance, 1e-10 rad,
    // times g' ~ a face's half-length where the minimum is a near-kink of two flat faces).
    const SuperPairContact wc = contact_pair(m.i.s, m.i.p, m.j.s, m.j.p);
    EXPECT_LT(angle_between(w.n, wc.n), 1e-8);
    EXPECT_NEAR(w.delta, wc.delta, 1e-8 * c.mtd.depth);
  }
  print_pair_stats(st);
  EXPECT_EQ(st.fallbacks, 0);
  EXPECT_EQ(st.midway_fallbacks, 0);
  EXPECT_EQ(st.failures, 0);
  // The solver finds the midway point of its definition; the point itself is ill-conditioned
  // where two flat faces meet (the level sets touch along a near-segment), the normal is not.
  EXPECT_LT(st.own_angle.max(), 1e-6);
  EXPECT_LT(st.own_point.quantile(0.9), 1e-6);
  // The contact is the penetration depth (the reference's own sweep is good to ~1e-9 rad).
  EXPECT_LT(st.mtd_angle.quantile(0.99), 1e-6);
  EXPECT_LT(st.mtd_angle.max(), 1e-5);
  EXPECT_LT(st.mtd_depth.quantile(0.99), 1e-6);
  EXPECT_LT(st.mtd_depth.max(), 1e-5);
  // The point is ill-conditioned where two flat faces meet near-parallel (the support points
  // slide along a face for a tiny turn of the normal, in the reference too): 99 % only, and that
  // quantile moves with the support points' round-off (6e-5 with pow alone, 1.3e-4 with the
  // whole exponents' square roots) while the normal's and the overlap's errors do not.
  EXPECT_LT(st.mtd_point.quantile(0.99), 2e-4);
}

// The kernel's solve: contact_depth cold gives contact_pair's contact; warm-started from the normal
// of the pose a step before, it converges in a few evaluations to the same contact.
TEST(SuperEllipse, DepthAloneWarmStartedFromTheLastNormalMatchesTheColdSolve) {
  std::mt19937_64 rng(2025);
  std::map<int, int> warm_evals;
  double worst_angle = 0.0;
  int slow = 0;
  for (int k = 0; k < kPairCases; ++k) {
    const PairCase c = random_pair(rng);
    const SuperPairContact r = contact_pair(c.i.s, c.i.p, c.j.s, c.j.p);
    const SuperPairContact d = contact_depth(c.i.s, c.i.p, c.j.s, c.j.p);
    ASSERT_TRUE(d.candidate && d.converged);
    EXPECT_LT(angle_between(d.n, r.n), 1e-8);
    EXPECT_NEAR(d.delta, r.delta, 1e-8 * c.mtd.depth);
    EXPECT_NEAR(std::cos(d.angle), d.n.x, 1e-15);
    EXPECT_NEAR(std::sin(d.angle), d.n.y, 1e-15);
    const PairCase m = moved(c, rng);
    DepthStart start;
    start.warm = true;
    start.phi = d.angle;
    const SuperPairContact w = contact_depth(m.i.s, m.i.p, m.j.s, m.j.p, start);
    const SuperPairContact wc = contact_depth(m.i.s, m.i.p, m.j.s, m.j.p);
    ++warm_evals[w.depth_iterations];
    EXPECT_TRUE(w.converged);
    slow += w.depth_iterations > 4 ? 1 : 0;
    worst_angle = std::max(worst_angle, angle_between(w.n, wc.n));
    EXPECT_NEAR(w.delta, wc.delta, 1e-8 * c.mtd.depth);
  }
  print_histogram("depth evaluations, warm from the last normal", warm_evals);
  std::printf("  warm against cold: normals %.3g rad apart at most\n", worst_angle);
  EXPECT_LT(worst_angle, 1e-8);
  // A few evaluations but where the minimum is a near-kink of two flat faces (bisection).
  EXPECT_LE(slow, kPairCases / 100);
}

// The closed forms of the ellipse (n = 2) and the whole exponents' products and square roots give
// the general path's values (pow, reached with n one ulp away) to round-off.
TEST(SuperEllipse, FastPathsOfWholeExponentsMatchThePowPath) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<> angle(-kPi, kPi), size(0.2, 3.0), scale(0.0, 1.5);
  double support_err = 0.0, kappa_err = 0.0, f_err = 0.0, grad_err = 0.0, hess_err = 0.0;
  for (const double n : {2.0, 4.0, 8.0, 6.0, 10.0}) {
    for (int k = 0; k < 2000; ++k) {
      const double a = size(rng), b = size(rng);
      const SuperEllipse fast{a, b, n}, slow{a, b, std::nextafter(n, 100.0)};
      const Vec2 u = unit(angle(rng));
      const SupportCurvature sf = support_curvature(fast, u), ss = support_curvature(slow, u);
      const Vec2 pf = support(fast, u);
      support_err = std::max(support_err, norm(pf - ss.p) / std::max(a, b));
      support_err = std::max(support_err, norm(sf.p - ss.p) / std::max(a, b));
      kappa_err = std::max(kappa_err, std::abs(sf.kappa - ss.kappa) / ss.kappa);
      const Vec2 x = scale(rng) * sf.p;
      const ImplicitValue ef = evaluate(fast, x), es = evaluate(slow, x);
      f_err = std::max(f_err, std::abs(ef.f - es.f) / (1.0 + std::abs(es.f)));
      grad_err = std::max(grad_err, norm(ef.grad - es.grad) / std::max(norm(es.grad), 1e-300));
      hess_err = std::max(hess_err, norm(ef.hess - es.hess) / std::max(norm(es.hess), 1e-300));
    }
  }
  std::printf("fast paths against pow: support %.3g, kappa %.3g, F %.3g, grad %.3g, hess %.3g\n",
              support_err, kappa_err, f_err, grad_err, hess_err);
  EXPECT_LT(support_err, 1e-12);
  EXPECT_LT(kappa_err, 1e-12);
  EXPECT_LT(f_err, 1e-12);
  EXPECT_LT(grad_err, 1e-12);
  EXPECT_LT(hess_err, 1e-12);
}

TEST(SuperEllipse, CirclesGiveTheDiscsOverlapOnTheLineOfCentres) {
  const SuperEllipse a{0.01, 0.01, 2.0}, b{0.007, 0.007, 2.0};
  const SuperPose pa{{0.1, 0.2}, 0.3}, pb{{0.1 + 0.0165, 0.2 + 0.002}, -1.1};
  const SuperPairContact r = contact_pair(a, pa, b, pb);
  const Vec2 d = pb.centre - pa.centre;
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.delta, 0.017 - norm(d), 1e-15);
  EXPECT_LT(angle_between(r.n, d), 1e-14);
  EXPECT_NEAR(r.rho_i, 0.01, 1e-15);
  EXPECT_NEAR(r.rho_j, 0.007, 1e-15);
}

TEST(SuperEllipse, DiscAgainstWallsMatchesTheDiscShape) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double r = 0.01;
  const SuperEllipse s{r, r, 2.0};
  const Vec2 a{-0.05, 0.0}, b{0.05, 0.01};
  int ends = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec2 x{-0.07 + 0.14 * U(rng), -0.012 + 0.024 * U(rng)};
    const WallGeometry g = Disc::segment(a, b, x, r);
    const SuperWallContact c = contact_segment(s, x, 6.0 * U(rng), a, b);
    ends += c.iterations > 0;
    // Past an end the normal is solved to the angle's tolerance, 1e-10 rad.
    EXPECT_NEAR(c.contact.g.delta, g.delta, 1e-13);
    EXPECT_LT(angle_between(c.contact.g.n, g.n), 2e-10);
    EXPECT_LT(norm(c.contact.g.point - g.point), 1e-13);
    EXPECT_LT(norm(c.contact.arm - r * g.n), 2e-10 * r);
  }
  EXPECT_GT(ends, 20);  // the ends were reached
  const Vec2 C{0.3, -0.2};
  const double R = 0.5;
  for (int k = 0; k < 100; ++k) {
    const Vec2 x = C + (R - r + 0.001 * (U(rng) - 0.5)) * unit(6.3 * U(rng));
    const WallGeometry g = Disc::inside_circle(C, R, x - C, norm(x - C), r);
    const SuperWallContact c = contact_inside_circle(s, x, 6.0 * U(rng), C, R);
    EXPECT_TRUE(c.converged);
    EXPECT_NEAR(c.contact.g.delta, g.delta, 1e-15);
    EXPECT_LT(angle_between(c.contact.g.n, g.n), 1e-12);
    EXPECT_LT(norm(c.contact.g.point - g.point), 1e-14);
  }
}

// ---- Walls against dense polygons
// ----------------------------------------------------------------

constexpr int kWallCases = 300;

struct WallStats {
  Stats depth, angle, point;
  int misses = 0, unconverged = 0;
  void add(const SuperWallContact& c, double depth, Vec2 n, Vec2 point, double size) {
    if (!c.converged) ++unconverged;
    if (depth > 0.0 && !(c.contact.g.delta > 0.0)) ++misses;
    this->depth.add(std::abs(c.contact.g.delta - depth) / size);
    angle.add(angle_between(c.contact.g.n, n));
    this->point.add(norm(c.contact.g.point - point) / size);
  }
  void print(const char* what) const {
    std::printf("%s, %d random poses (aspect 1-4, n 2-10):\n", what, kWallCases);
    depth.print("|overlap - polygon's| / size");
    angle.print("normal vs polygon's (rad)");
    point.print("|point - polygon's| / size");
    std::printf("  contacts missed: %d, not converged: %d\n", misses, unconverged);
  }
};

// The polygons' accuracy (8000 vertices): ~1e-7 of the size in a distance, ~1e-3 rad in a normal
// on a flat face's corner (the polygon's own edges' normals), less elsewhere.
void expect_wall_accuracy(const WallStats& st) {
  EXPECT_EQ(st.misses, 0);
  EXPECT_EQ(st.unconverged, 0);
  EXPECT_LT(st.depth.quantile(0.99), 1e-6);
  EXPECT_LT(st.depth.max(), 1e-5);
  EXPECT_LT(st.angle.quantile(0.99), 2e-3);
  EXPECT_LT(st.point.quantile(0.99), 1e-3);
}

// A segment of 0.2-3 sizes at a random angle crossing the body's deepest point by 0.1-5 % of the
// size, shifted along itself so that the point falls on it or up to a size past either end (the
// thin tilted body crossing near an end among them). The reference: the exact penetration depth of
// the polygon and the segment (a two-vertex polygon), its wall point on the segment.
TEST(SuperEllipse, SegmentMatchesDensePolygons) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  WallStats st;
  int ends = 0, former_off = 0, former_missed = 0;
  for (int k = 0; k < kWallCases; ++k) {
    const Body b = random_body(rng);
    const double size = bounding_radius(b.s);
    // From the body to the wall; a quarter of the poses have a long face nearly along the wall,
    // tilted by up to 0.1 rad, with the deepest point (a corner) past the end by up to 0.3 size.
    const bool tilted = k % 4 == 0;
    const double along_face = b.p.theta + 0.5 * kPi * (U(rng) < 0.5 ? 1.0 : -1.0);
    const Vec2 m = tilted ? unit(along_face + 0.2 * (U(rng) - 0.5)) : unit(2.0 * kPi * U(rng));
    const Vec2 p = support_lab(b.s, b.p.centre, b.p.theta, m);
    const double overlap = size * std::exp(std::log(0.001) + U(rng) * std::log(50.0));
    const double len = size * (0.2 + 2.8 * U(rng));
    const double end = (U(rng) < 0.5 ? 0.5 : -0.5) * len;
    const double shift = tilted       ? end + std::copysign(0.3 * size * U(rng), end)
                         : k % 2 == 1 ? (U(rng) - 0.5) * len
                                      : end + (U(rng) - 0.5) * size;
    const Vec2 a = p - overlap * m + (shift - 0.5 * len) * perp(m);
    const Vec2 e = a + len * perp(m);
    const DepthRef ref = polygon_depth(polygon(b, 8000), {a, e});
    if (!(ref.depth > 1e-4 * size)) continue;  // apart, or barely touching
    const SuperWallContact c = contact_segment(b.s, b.p.centre, b.p.theta, a, e);
    ends += c.iterations > 0;
    // The former rule past an end: the nearer end's point contact alone.
    const double t = dot(p - a, perp(m));
    if (t < 0.0 || t > len) {
      const Vec2 x = t < 0.0 ? a : e;
      const SuperWallContact old = contact_point(b.s, b.p.centre, b.p.theta, x);
      former_off += std::abs(old.contact.g.delta - ref.depth) > 1e-3 * size;
      former_missed += !(old.contact.g.delta > 0.0);
    }
    const Vec2 q = ref.pi - ref.depth * ref.n;
    const double along = std::clamp(dot(q - a, perp(m)), 0.0, len);
    st.add(c, ref.depth, ref.n, a + along * perp(m), size);
  }
  st.print("segment");
  std::printf(
      "  past an end: %d; the nearer end's point contact alone off by > 1e-3 size: %d, "
      "of them no contact: %d\n",
      ends, former_off, former_missed);
  expect_wall_accuracy(st);
  EXPECT_GT(ends, 40);
}

// A thin body tilted across a segment's end, deep enough that its deepest point (the tip) projects
// past the end while the body still crosses the segment and the end lies outside it: the end's
// point contact alone reads as no contact; the penetration depth (the polygons') is found. Up to
// a thickness deep: deeper, the two-sided polygons' depth may push the body on through the segment
// (the wall's side is the one away from the centre).
TEST(SuperEllipse, SegmentCrossedNearItsEndByATiltedTip) {
  int checked = 0;
  for (double n : {2.0, 4.0, 10.0})
    for (double tilt : {0.4, 0.7, 1.0})
      for (double depth : {1.0, 1.5, 2.0}) {
        const Body b{{0.02, 0.005, n}, {{0.0, 0.0}, -tilt}};
        const double size = bounding_radius(b.s);
        const Vec2 tip = support_lab(b.s, b.p.centre, b.p.theta, {0.0, -1.0});
        const double y = tip.y + depth * b.s.b;  // the line, 1-2 half-thicknesses above the tip
        // The body's chord [x1, x2] on the line: its points with F <= 0.
        double x1 = 1.0, x2 = -1.0;
        for (int k = 0; k <= 40000; ++k) {
          const double x = -0.03 + 0.06 * k / 40000.0;
          if (implicit(b.s, rotate(Vec2{x, y}, tilt)) <= 0.0) x1 = std::min(x1, x), x2 = x;
        }
        if (tip.x > x1 - 1e-4 && tip.x < x2 + 1e-4) continue;  // the tip projects onto the chord
        // The end between the chord and the tip, the segment running over the chord.
        const double x_end = tip.x > x2 ? 0.5 * (x2 + tip.x) : 0.5 * (x1 + tip.x);
        const Vec2 e{x_end, y}, a{tip.x > x2 ? x1 - 0.05 : x2 + 0.05, y};
        const SuperWallContact c = contact_segment(b.s, b.p.centre, b.p.theta, a, e);
        const SuperWallContact former = contact_point(b.s, b.p.centre, b.p.theta, e);
        const DepthRef ref = polygon_depth(polygon(b, 8000), {a, e});
        EXPECT_LT(former.contact.g.delta, 0.0) << n << " " << tilt;
        EXPECT_GT(ref.depth, 0.0);
        EXPECT_NEAR(c.contact.g.delta, ref.depth, 1e-6 * size) << n << " " << tilt;
        EXPECT_LT(angle_between(c.contact.g.n, ref.n), 2e-3) << n << " " << tilt;
        ++checked;
      }
  std::printf("tilted tip past a segment's end: %d poses\n", checked);
  EXPECT_GT(checked, 4);
}

// The drum's circle (R = 0.5 m) holding a body whose farthest point reaches 0.1-5 % of its size
// beyond it; the reference: the polygon's farthest vertex from the circle's centre.
TEST(SuperEllipse, InsideCircleMatchesDensePolygons) {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const Vec2 C{0.3, -0.2};
  const double R = 0.5;
  WallStats st;
  for (int k = 0; k < kWallCases; ++k) {
    Body b = random_body(rng);
    const double size = bounding_radius(b.s);
    const Vec2 dir = unit(2.0 * kPi * U(rng));
    const double overlap = size * std::exp(std::log(0.001) + U(rng) * std::log(50.0));
    b.p.centre = C + (R - size + overlap) * dir;
    double far = 0.0;
    Vec2 v_far{};
    for (const Vec2 v : polygon(b, 8000))
      if (norm(v - C) > far) far = norm(v - C), v_far = v;
    const Vec2 n = (1.0 / far) * (v_far - C);
    const SuperWallContact c = contact_inside_circle(b.s, b.p.centre, b.p.theta, C, R);
    st.add(c, far - R, n, C + R * n, size);
  }
  st.print("inside a circle");
  expect_wall_accuracy(st);
}

// A point 0-5 % of the size inside or outside the curve near a random boundary point; the
// reference: the nearest point of the polygon's edges (signed distance, > 0 inside) and the normal
// there.
TEST(SuperEllipse, PointMatchesDensePolygons) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  WallStats st;
  Stats arm;
  for (int k = 0; k < kWallCases; ++k) {
    const Body b = random_body(rng);
    const double size = bounding_radius(b.s);
    const Vec2 on = support_lab(b.s, b.p.centre, b.p.theta, unit(2.0 * kPi * U(rng)));
    const Vec2 e = on + (0.05 * size * U(rng)) * unit(2.0 * kPi * U(rng));
    const std::vector<Vec2> P = polygon(b, 8000);
    double best = 1e300;
    Vec2 q{};
    bool inside = true;
    for (std::size_t v = 0; v < P.size(); ++v) {
      const Vec2 x = P[v], y = P[(v + 1) % P.size()];
      inside = inside && cross(y - x, e - x) >= 0.0;
      const double t = std::clamp(dot(e - x, y - x) / norm2(y - x), 0.0, 1.0);
      if (norm(x + t * (y - x) - e) < best) best = norm(x + t * (y - x) - e), q = x + t * (y - x);
    }
    const Vec2 n = (inside ? -1.0 / best : 1.0 / best) * (e - q);
    const SuperWallContact c = contact_point(b.s, b.p.centre, b.p.theta, e);
    st.add(c, inside ? best : -best, n, e, size);
    arm.add(norm(c.contact.arm - (q - b.p.centre)) / size);
  }
  st.print("point");
  arm.print("|body point - polygon's| / size");
  expect_wall_accuracy(st);
  EXPECT_LT(arm.quantile(0.99), 1e-3);
}

// The cost per call (printed): cold and warm pair solves, segment and circle contacts.
}  // namespace
}  // namespace dem2d
